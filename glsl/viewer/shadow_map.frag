#version 330 core
// The viewer's shadow-map view (renderer/viewer/shadow_view.py; no NumPy twin: it shows a map, it is
// no stage of the pipeline). With glsl/raytrace/fullscreen.vert, drawn with the viewport on the
// rectangle the map fills: one light's map as grey levels, the stored depth z_w stretched from the
// nearest depth the map holds (black) to the farthest (STRETCH_TOP, light grey), and 1.0, the cleared
// value (nothing drawn there), white: the depths of a light view may span a sliver of [0, 1], too
// little to see unstretched. A directional light's map is one square; a point light's six cube
// faces a 3 x 2 grid, faces 0 1 2 (+x -x +y) on top, 3 4 5 (-y +z -z) below. Each face shows
// texels [0, R)^2 of its layer, GL rows (row 0 at the bottom, as the depth pass drew it), nearest
// texel: texelFetch, no filtering.

uniform sampler2DArray u_maps;     // the maps' array texture through a sampler object with compare off
uniform vec4 u_region;             // (x0, y0, width, height): the viewport, window pixels
uniform ivec2 u_grid;              // faces across and down: (1, 1) or (3, 2)
uniform int u_first_layer;         // the layer of face 0
uniform int u_resolution;          // R
uniform vec2 u_depth_range;        // (nearest, farthest) depth below 1.0 in the map's drawn faces
uniform int u_drawn_faces;         // bit f set: face f was drawn this frame (else shown white: the
                                   // lookup reads an undrawn face as lit without reading it)

out vec4 out_color;

#define STRETCH_TOP 0.85          // the farthest stored depth's grey: apart from the cleared white

void main() {
    vec2 p = (gl_FragCoord.xy - u_region.xy) / u_region.zw * vec2(u_grid);
    ivec2 cell = clamp(ivec2(floor(p)), ivec2(0), u_grid - 1);
    int face = (u_grid.y - 1 - cell.y) * u_grid.x + cell.x;          // top row first
    ivec2 texel = clamp(ivec2(floor((p - vec2(cell)) * float(u_resolution))),
                        ivec2(0), ivec2(u_resolution - 1));
    float grey = 1.0;
    if (((u_drawn_faces >> face) & 1) != 0) {
        float depth = texelFetch(u_maps, ivec3(texel, u_first_layer + face), 0).r;
        float span = max(u_depth_range.y - u_depth_range.x, 1e-30);
        if (depth < 1.0) {
            grey = STRETCH_TOP * clamp((depth - u_depth_range.x) / span, 0.0, 1.0);
        }
    }
    out_color = vec4(vec3(grey), 1.0);
}
