// benches/scenes/gyroid.scn in POV-Ray 3.7:
//   povray +Igyroid.pov +W1000 +H1000 -A File_Gamma=1.0 +Ogyroid-pov.png
// (linear output, like scnc's default)
// Matched to scnc's model as glass-sphere.pov is (ambient, N·L diffuse, Phong highlights,
// max_trace_level = scnc's depth + 1). The sheet is an isosurface contained_by the ball
// rather than a CSG intersection with it, which (without all_intersections) keeps only
// the first root and loses half the sheet. sin and cos take radians here: 450° is 2.5π.
#version 3.7;
global_settings { assumed_gamma 1.0 ambient_light rgb 1 max_trace_level 6 adc_bailout 0 }

camera {
  location <3.2, 2.4, -4.2>
  look_at <0, 0, 0>
  right x
  angle 40
}
background { rgb <30, 34, 44> / 255 }
light_source { <5, 8, -6> color rgb 0.7 }
light_source { <-6, 3, -4> color rgb 0.4 }

#declare K = 2.5 * pi;
isosurface {
  function { abs(sin(K * x) * cos(K * y) + sin(K * y) * cos(K * z) + sin(K * z) * cos(K * x)) - 0.3 }
  contained_by { sphere { 0, 1.6 } }
  max_gradient 14
  accuracy 1e-4
  pigment { rgb <230, 150, 60> / 255 }
  // scnc weighs a reflective surface's own shading by 1 - reflective (0.8), POV-Ray does not.
  finish { ambient 0.16 diffuse 0.8 phong 0.8 phong_size 40 reflection { 0.2 } }
}
