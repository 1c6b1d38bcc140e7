// Twin: reference/radiosity/item_buffer.py
#version 330 core
// Each triangle to its face's layer of the item buffers (gl_Layer: the instance, one layer a
// hemicube face), carrying which element it is: the draw's primitive index, the element's
// index in renderer/core/radiosity_elements.py's order (one triangle an element, drawn in order).

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

flat in int v_face[];
flat out int g_element;
flat out int g_side;                // 1 on a side face (hemicube.FACES: every face but the first of five)

void main() {
    for (int k = 0; k < 3; ++k) {
        gl_Position = gl_in[k].gl_Position;
        gl_Layer = v_face[0];
        g_element = gl_PrimitiveIDIn;
        g_side = v_face[0] % 5 == 0 ? 0 : 1;
        EmitVertex();
    }
    EndPrimitive();
}
