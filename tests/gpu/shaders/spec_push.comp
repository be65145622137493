// values[i] = sign * (float((base + i) * kMultiplier) * scale + kOffset); also reports the
// work-group size that specialisation constant 0 set.
#version 450

layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint kMultiplier = 1u;
layout(constant_id = 2) const float kOffset = 0.0;
layout(constant_id = 3) const bool kNegate = false;

layout(push_constant) uniform Params {
    uint base;
    uint count;
    float scale;
} params;

layout(set = 0, binding = 0) writeonly buffer Values { float values[]; };
layout(set = 0, binding = 1) writeonly buffer Info { uint groupSize; uint groupCount; };

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i == 0u) {
        groupSize = gl_WorkGroupSize.x;
        groupCount = gl_NumWorkGroups.x;
    }
    if (i >= params.count)
        return;
    float v = float((params.base + i) * kMultiplier) * params.scale + kOffset;
    values[i] = kNegate ? -v : v;
}
