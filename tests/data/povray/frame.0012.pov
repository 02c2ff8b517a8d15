// vfield: frame 12 for POV-Ray 3.7. Coordinates are vfield's mirrored in z.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 8 }

camera {
  perspective
  location <0, 6, -25>
  direction <0, -0.1579905011, 0.9874406319>
  right <1.472759333, 0, 0>
  up <0, 0.8180226036, 0.1308836166>
}

sky_sphere {
  pigment {
    function { pow(min(max(2 * y, 0), 1), 2) * (3 - 2 * min(max(2 * y, 0), 1)) }
    color_map { [0 rgb <0.55, 0.68, 0.9>] [1 rgb <0.12, 0.28, 0.75>] }
  }
}

light_source {
  <423999.152, 847998.304, -317999.364>
  color rgb <0.9549296586, 0.9167324722, 0.8594366927>
  parallel point_at <0, 0, 0>
  media_interaction on media_attenuation on
}
light_source {
  <0, 1e6, 0>
  color rgb <-0.0475, 0.04, 0.3375>
  parallel point_at <0, 0, 0>
  shadowless media_interaction off
}
#default { finish { ambient rgb <0.1675, 0.24, 0.4125> diffuse 1 specular 0 phong 0 } }

#include "meshes.inc"
object { VF_Object_0 }
object { VF_Object_1 }
object { VF_Object_2
  matrix <1.732050808, 0, 1,
      0.1736481777, 1.969615506, -0.3007674664,
      -0.984807753, 0.3472963553, 1.705737064,
      -4, 3, -2>
}

box { <0, 0, 0>, <1, 1, 1>
  hollow
  texture { pigment { rgbt 1 } }
  interior {
    media {
      method 3 intervals 1 samples 26
      absorption rgb 0.2
      scattering { 5, rgb 0.45 eccentricity 0.3 extinction 4 }
      density { density_file df3 "density.0012.df3" interpolate 1 }
    }
    media {
      method 3 intervals 1 samples 26
      emission rgb <0.69975, 0.954, 1.51875>
      scattering { 5, rgb 0 eccentricity 0.3 }
      density { density_file df3 "sky_lit.0012.df3" interpolate 1 }
    }
  }
  scale <4, 4, -3>
  translate <1, 4, 1>
}
