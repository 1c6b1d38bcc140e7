// Twin: reference/output/colour.py
// CIE XYZ and chromaticity of linear RGB in float32 (notes 1.2 "Colour"; renderer/core/colour.py
// derives the matrix from the sRGB primaries and D65 and hands it here as a uniform).
// Plain multiplies and adds: llvmpipe fuses none of them (lower_ffma32), and the twin in float64
// agrees within the bound tests/test_colour.py states.

uniform mat3 rgb_to_xyz_matrix;     // RGB_TO_XYZ (GL takes it column by column: transpose=True)
uniform vec3 white_chromaticity;    // D65's x, y, z: what black, which has none, is given

vec3 rgb_to_xyz(vec3 rgb)
{
    return rgb_to_xyz_matrix * rgb;
}

float luminance(vec3 rgb)          // CIE Y: the matrix's middle row
{
    return rgb_to_xyz(rgb).y;
}

// x, y, z = X, Y, Z / (X + Y + Z); no light (a sum <= 0) has the white point's.
vec3 chromaticity(vec3 xyz)
{
    float sum = xyz.x + xyz.y + xyz.z;
    return sum > 0.0 ? xyz / sum : white_chromaticity;
}
