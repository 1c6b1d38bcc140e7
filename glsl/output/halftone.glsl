// Twin: reference/output/halftone.py
// Half-toning with clustered (diamond) dots, one screen per ink C, M, Y, K, the inks binary:
// the rule, its area law and why a diamond are in the twin's docstring. Every operation is one
// float32 operation of the twin's, in its order (llvmpipe fuses no multiply-add). Needs
// clamp_light (quantise.glsl).

uniform vec2 u_screen[4];   // (cs, sn) = (cos a, sin a) / cell of inks C, M, Y, K (renderer/core/halftone_screen.py)

// The diamond dot's threshold S in [0, 1] at pixel centre `centre` on the screen `basis`:
// {S < a} covers exactly a fraction a of each cell.
float spot_threshold(vec2 centre, vec2 basis) {
    float u = centre.x * basis.x + centre.y * basis.y;     // cell coordinates, turned by a
    float v = centre.y * basis.x - centre.x * basis.y;
    float fu = (u - floor(u)) - 0.5;                       // from the cell's centre
    float fv = (v - floor(v)) - 0.5;
    float t = abs(fu) + abs(fv);
    return t <= 0.5 ? 2.0 * (t * t) : 1.0 - 2.0 * ((1.0 - t) * (1.0 - t));
}

// The 1-bit codes of R, G, B at pixel p (column, image row from the top): 0 where the
// channel's ink (C, M, Y) or black is printed, 1 where the paper shows.
uvec3 halftone_codes(vec3 light, uvec2 p) {
    vec3 coverage = vec3(1.0) - vec3(clamp_light(light.r), clamp_light(light.g), clamp_light(light.b));
    float k = min(min(coverage.r, coverage.g), coverage.b);    // grey-component replacement
    vec2 centre = vec2(p) + 0.5;
    float paper = 1.0 - k;
    bool black = k > spot_threshold(centre, u_screen[3]);
    // c' = (c - k) / (1 - k) > S, without the division
    bool cyan = coverage.r - k > spot_threshold(centre, u_screen[0]) * paper;
    bool magenta = coverage.g - k > spot_threshold(centre, u_screen[1]) * paper;
    bool yellow = coverage.b - k > spot_threshold(centre, u_screen[2]) * paper;
    return uvec3(!(cyan || black), !(magenta || black), !(yellow || black));
}
