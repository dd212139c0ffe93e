#version 450 core
// The caustic resolve's tiles (CausticTiles.h tileQuads): quads in GL normalised device
// coordinates, at depth 0; the resolve reads its pixel from gl_FragCoord.
layout(location = 0) in vec2 position;
void main() { gl_Position = vec4(position, 0.0, 1.0); }
