// Twin: reference/output/halftone.py
// Half-toning with clustered (diamond) dots, one screen per ink C, M, Y, K, the inks binary:
// the rule, its area law and why a diamond are in the twin's docstring. Every operation is one
// float32 operation of the twin's, in its order (llvmpipe fuses no multiply-add). Needs
// clamp_light (quantise.glsl).

uniform vec2 u_screen[4];   // (cs, sn) = (cos a, sin a) / cell of inks C, M, Y, K (renderer/core/halftone_screen.py)
// A screen on the pixel grid (a multiple of 90 degrees, a whole-pixel cell) reads its threshold
// array instead of S, whose samples there tie on each diamond (halftone_screen.py, grid_screens):
uniform uint u_grid_cell[4];            // ink i's cell where its screen is on the grid, else 0
uniform sampler2D u_grid_thresholds;    // ink i's array in texel rows i cell .. (i + 1) cell - 1

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

// Ink i's threshold at pixel p (its centre `centre`): its array's entry on the pixel grid, else S.
float ink_threshold(uint ink, uvec2 p, vec2 centre) {
    uint cell = u_grid_cell[ink];
    if (cell > 0u) {
        return texelFetch(u_grid_thresholds, ivec2(p.x % cell, ink * cell + p.y % cell), 0).r;
    }
    return spot_threshold(centre, u_screen[ink]);
}

// The 1-bit codes of R, G, B at pixel p (column, image row from the top): 0 where the
// channel's ink (C, M, Y) or black is printed, 1 where the paper shows.
uvec3 halftone_codes(vec3 light, uvec2 p) {
    vec3 coverage = vec3(1.0) - vec3(clamp_light(light.r), clamp_light(light.g), clamp_light(light.b));
    float k = min(min(coverage.r, coverage.g), coverage.b);    // grey-component replacement
    vec2 centre = vec2(p) + 0.5;
    float paper = 1.0 - k;
    bool black = k > ink_threshold(3u, p, centre);
    // c' = (c - k) / (1 - k) > S, without the division
    bool cyan = coverage.r - k > ink_threshold(0u, p, centre) * paper;
    bool magenta = coverage.g - k > ink_threshold(1u, p, centre) * paper;
    bool yellow = coverage.b - k > ink_threshold(2u, p, centre) * paper;
    return uvec3(!(cyan || black), !(magenta || black), !(yellow || black));
}
