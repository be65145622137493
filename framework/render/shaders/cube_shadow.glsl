// Cube-map faces of the shadow atlas: the GLSL twin of computeCubeFace, computeCubeFaceCoords
// and computeCubeFaceDirection in render/shadow_pass.{h,cpp} (Vulkan cube-map table; face =
// major axis +x, -x, +y, -y, +z, -z; coordinates (s, t) in [-1, 1], t = texel row).
#ifndef RTLAB_CUBE_SHADOW_GLSL
#define RTLAB_CUBE_SHADOW_GLSL

// Major-axis face of d (ties go to x, then y).
int computeCubeFace(vec3 d)
{
    const vec3 a = abs(d);
    if (a.x >= a.y && a.x >= a.z)
        return d.x >= 0.0 ? 0 : 1;
    if (a.y >= a.z)
        return d.y >= 0.0 ? 2 : 3;
    return d.z >= 0.0 ? 4 : 5;
}

// (s, t) of d on `face`: the (right, up) components of d over its component along the axis.
vec2 computeCubeFaceCoords(vec3 d, int face)
{
    switch (face) {
    case 0: return vec2(-d.z, -d.y) / d.x;
    case 1: return vec2(d.z, -d.y) / -d.x;
    case 2: return vec2(d.x, d.z) / d.y;
    case 3: return vec2(d.x, -d.z) / -d.y;
    case 4: return vec2(d.x, -d.y) / d.z;
    default: return vec2(-d.x, -d.y) / -d.z;
    }
}

// The direction axis + s right + t up of face coordinates st.
vec3 computeCubeFaceDirection(int face, vec2 st)
{
    switch (face) {
    case 0: return vec3(1.0, -st.y, -st.x);
    case 1: return vec3(-1.0, -st.y, st.x);
    case 2: return vec3(st.x, 1.0, st.y);
    case 3: return vec3(st.x, -1.0, -st.y);
    case 4: return vec3(st.x, -st.y, 1.0);
    default: return vec3(-st.x, -st.y, -1.0);
    }
}

#endif
