// A deliberately slow kernel for timing tests: `iterations` rounds of an integer hash per
// element. The result is checked so the work cannot be optimised away.
#version 450

layout(local_size_x = 64) in;

layout(push_constant) uniform Params {
    uint count;
    uint iterations;
} params;

layout(set = 0, binding = 0) buffer Data { uint data[]; };

uint mixBits(uint v)
{
    v ^= v >> 16;
    v *= 0x7feb352du;
    v ^= v >> 15;
    v *= 0x846ca68bu;
    v ^= v >> 16;
    return v;
}

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= params.count)
        return;
    uint v = data[i];
    for (uint k = 0u; k < params.iterations; ++k)
        v = mixBits(v + k);
    data[i] = v;
}
