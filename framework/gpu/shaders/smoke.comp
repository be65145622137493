// The smoke shader: y = a * x + y over `count` floats. Work-group size is specialisation
// constant 0.
#version 450

layout(local_size_x_id = 0) in;

layout(push_constant) uniform Params {
    float a;
    uint count;
} params;

layout(set = 0, binding = 0) readonly buffer InputX {
    float x[];
};

layout(set = 0, binding = 1) buffer InOutY {
    float y[];
};

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i < params.count)
        y[i] = params.a * x[i] + y[i];
}
