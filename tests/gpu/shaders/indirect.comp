#version 450
// dispatchIndirect's test: mode 0 (one invocation) writes the group count for `count` items in
// groups of 64 into args; mode 1 marks every invocation it runs as in the given group count.
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer Args { uint args[4]; }; // x, y, z, count
layout(std430, binding = 1) buffer Marks { uint marks[]; };
layout(push_constant) uniform Push { uint mode; } pc;
void main()
{
    const uint i = gl_GlobalInvocationID.x;
    if (pc.mode == 0u) {
        if (i == 0u) {
            args[0] = (args[3] + 63u) / 64u;
            args[1] = 1u;
            args[2] = 1u;
        }
        return;
    }
    marks[i] = 1u;
}
