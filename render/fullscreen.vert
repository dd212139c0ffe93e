#version 450 core
// Full-screen triangle from gl_VertexID (no vertex buffer). uv in [0,1] over the viewport;
// uv.y = 0 is memory row 0 (the image's top row: mirage keeps images top-row-first).
out vec2 uv;
void main() {
    vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    uv = p;
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
