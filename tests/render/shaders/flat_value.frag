#version 450
// Writes the flat value, and a colour from push constants whose alpha tells the facing:
// +1 front, -1 back.

layout(push_constant) uniform Params {
    vec4 color;
} params;

layout(location = 0) flat in uint inValue;

layout(location = 0) out uint outValue;
layout(location = 1) out vec4 outColor;

void main()
{
    outValue = inValue;
    outColor = vec4(params.color.rgb, gl_FrontFacing ? 1.0 : -1.0);
}
