// Twin: reference/shadow/depth.py
#version 330 core
// The light-view depth pass's fragments write no colour: the rasteriser's depth z_w (depth
// test GL_LESS against the tile, cleared to 1) is all a shadow map holds.

void main() {
}
