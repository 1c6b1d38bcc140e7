// Twin: reference/output/colour.py
#version 430 core
// The colour pass (renderer/gpu/colour.py): per pixel of a linear frame, its CIE XYZ (alpha kept)
// and its chromaticity x, y, z. Image row r is texel row r (nothing flipped): the frame's row 0
// is at the top.

layout(local_size_x = GROUP_SIZE, local_size_y = GROUP_SIZE) in;   // renderer/gpu/colour.py's GROUP
layout(rgba32f, binding = 0) uniform readonly image2D linear_image;
layout(rgba32f, binding = 1) uniform writeonly image2D xyz_image;
layout(rgba32f, binding = 2) uniform writeonly image2D chromaticity_image;

#include "colour.glsl"

void main()
{
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, imageSize(linear_image))))
        return;
    vec4 linear = imageLoad(linear_image, pixel);
    vec3 xyz = rgb_to_xyz(linear.rgb);
    imageStore(xyz_image, pixel, vec4(xyz, linear.a));
    imageStore(chromaticity_image, pixel, vec4(chromaticity(xyz), 0.0));
}
