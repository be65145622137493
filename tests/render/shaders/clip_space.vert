#version 450
// Positions given in clip space; a per-vertex value passed on flat (from the provoking vertex).

layout(location = 0) in vec4 inPosition;
layout(location = 1) in uint inValue;

layout(location = 0) flat out uint outValue;

void main()
{
    outValue = inValue;
    gl_Position = inPosition;
}
