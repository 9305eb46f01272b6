#version 460
// The shade pass: one triangle over the whole screen (the scissor picks the tile): vertices (-1,-1), (3,-1), (-1,3).
void main() {
    vec2 p = vec2(float((gl_VertexIndex << 1) & 2), float(gl_VertexIndex & 2));
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
