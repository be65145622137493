// y = a * x + y, with the product rounded before the sum (precise), so the CPU can reproduce
// every result bit for bit.
#version 450
#include <test_common.glsl>

layout(local_size_x = 64) in;

layout(push_constant) uniform Params {
    float a;
    uint count;
} params;

layout(set = 0, binding = 0) readonly buffer InputX { float x[]; };
layout(set = 0, binding = 1) buffer InOutY { float y[]; };

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (!isInRange(i, params.count))
        return;
    precise float product = params.a * x[i];
    precise float sum = product + y[i];
    y[i] = sum;
}
