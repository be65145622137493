// Shared by the test shaders (found through the compiler's include directory).
#ifndef TEST_COMMON_GLSL
#define TEST_COMMON_GLSL

bool isInRange(uint index, uint count)
{
    return index < count;
}

#endif
