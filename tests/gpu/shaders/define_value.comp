// Writes the preprocessor value VALUE (given as a define) and whether FLAG is defined.
#version 450

layout(local_size_x = 1) in;
layout(set = 0, binding = 0) writeonly buffer Out { uint value; uint flag; };

void main()
{
    value = VALUE;
#ifdef FLAG
    flag = 1u;
#else
    flag = 0u;
#endif
}
