// glass-sphere.scn in POV-Ray 3.7: povray +Iglass-sphere.pov +W480 +H360 -A +Oglass-sphere-pov.png
// Matched to scnc's model: ambient 0.25 (POV's ambient_light 1, finish ambient 0.25),
// diffuse N·L (diffuse 1, brilliance 1), Phong highlights in the light's colour, clear
// glass as transmit 1 with exact Fresnel reflection (conserve_energy), max_trace_level
// = scnc's depth + 1 (POV counts the camera ray), no adaptive bailout.
#version 3.7;
global_settings { assumed_gamma 1.0 ambient_light rgb 1 max_trace_level 9 adc_bailout 0 }

// scnc's fov is vertical (45°); POV's angle is horizontal: 2·atan(tan(22.5°)·4/3).
camera {
  location <0, 2.2, -6>
  look_at <0, 0.8, 0>
  right x * 4 / 3
  angle 2 * degrees(atan(tan(radians(22.5)) * 4 / 3))
}
background { rgb <160, 190, 235> / 255 }
light_source { <4, 8, -5> color rgb 0.75 }

plane {
  y, 0
  // POV-Ray reads the floor at y = 0 and scnc just inside it (y < 0), so the cell
  // parities differ by one: the colours are listed the other way round.
  pigment { checker rgb 45 / 255, rgb 235 / 255 }
  finish { ambient 0.25 diffuse 1 }
}

sphere {
  <0, 1, 0>, 1
  pigment { rgbt <1, 1, 1, 1> }
  finish { ambient 0.25 diffuse 1 phong 1 phong_size 80 reflection { 0, 1 fresnel on } conserve_energy }
  interior { ior 1.5 }
}
