#version 450 core
// lucent GLSL 1: copies an image of the viewport's size texel for texel (fur over a mesh: the skin
// rendered by the maps, under the shells).
layout(location = 0) out vec4 out_color;
uniform sampler2D u_image;  // rows bottom-up

void main() { out_color = vec4(texelFetch(u_image, ivec2(gl_FragCoord.xy), 0).rgb, 1.0); }
