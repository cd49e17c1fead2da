// examples/povray/sweeps.scn in POV-Ray 3.7: povray +Isweeps.pov +W400 +H300 -A File_Gamma=1.0 +Osweeps-pov.png
// prism points are <x, z> swept along y, lathe points <radius, y>, as extrude and revolve
// read [u, v]; each outline closed by repeating its first point, as POV-Ray requires.
#version 3.7;
global_settings { assumed_gamma 1.0 ambient_light rgb 1 max_trace_level 1 }
camera { location <0, 3, -7> look_at <0, 0, 0> right x * 4 / 3 angle 57.822401637 }
background { rgb 0 }
prism { linear_sweep linear_spline -0.3, 0.3, 7, <-0.800000000, -0.500000000>, <0.800000000, -0.500000000>, <0.800000000, -0.100000000>, <-0.200000000, -0.100000000>, <-0.200000000, 0.600000000>, <-0.800000000, 0.600000000>, <-0.800000000, -0.500000000>
  pigment { rgb <1, 0, 0> } finish { ambient 1 diffuse 0 } translate <-2.2, 0.3, 0> }
prism { linear_sweep linear_spline -0.2, 0.2, 11, <0.900000000, 0.000000000>, <0.323606798, 0.235114101>, <0.278115295, 0.855950865>, <-0.123606798, 0.380422607>, <-0.728115295, 0.529006727>, <-0.400000000, 0.000000000>, <-0.728115295, -0.529006727>, <-0.123606798, -0.380422607>, <0.278115295, -0.855950865>, <0.323606798, -0.235114101>, <0.900000000, 0.000000000>
  pigment { rgb <0, 1, 0> } finish { ambient 1 diffuse 0 } translate <0, -0.6, -1.2> }
lathe { linear_spline 11, <0.000000000, -1.000000000>, <0.500000000, -1.000000000>, <0.550000000, -0.900000000>, <0.300000000, -0.400000000>, <0.350000000, 0.100000000>, <0.600000000, 0.600000000>, <0.550000000, 0.650000000>, <0.280000000, 0.120000000>, <0.220000000, -0.400000000>, <0.000000000, -0.600000000>, <0.000000000, -1.000000000>
  pigment { rgb <0, 0, 1> } finish { ambient 1 diffuse 0 } translate <0.2, 0.4, 1> }
lathe { linear_spline 4, <0.300000000, -0.500000000>, <0.700000000, -0.500000000>, <0.500000000, 0.500000000>, <0.300000000, -0.500000000>
  pigment { rgb <1, 1, 0> } finish { ambient 1 diffuse 0 } translate <2.3, 0, 0> }
