// Twin: reference/radiosity/item_buffer.py
#version 330 core
// The item: which element a hemicube pixel sees, and from which side (renderer/core/hemicube.py
// ITEM rules): its index + 1 when its front faces the hemicube, with bit ITEM_BACK_SHIFT set when its
// back does (an occluder that passes nothing on); 0, the clear value, where nothing is seen.
// A side face's lower half lies below the element's plane (hemicube.py): nothing is drawn there.

flat in int g_element;
flat in int g_side;

uniform float u_horizon;            // N / 2: a side face's rows below it are below the element

out uint item;

void main() {
    if (g_side == 1 && gl_FragCoord.y < u_horizon)
        discard;                    // no item, no depth: as if not drawn
    uint seen = uint(g_element) + 1u;
    item = gl_FrontFacing ? seen : (seen | (1u << ITEM_BACK_SHIFT));
}
