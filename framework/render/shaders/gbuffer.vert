#version 450
// G-buffer pass, vertex stage: positions relative to the camera (keeps precision far from the
// origin), shading normals, and the material of the triangle on its first (provoking) vertex.

#include "gbuffer_frame.glsl"

layout(location = 0) in vec3 inPosition; // world units
layout(location = 1) in vec3 inNormal;   // world space, unit length
layout(location = 2) in uint inMaterial; // material of the triangles this vertex starts
layout(location = 3) in vec3 inAlbedo;
layout(location = 4) in vec3 inEmission;

layout(location = 0) out vec3 outRelative; // world position - camera position
layout(location = 1) out vec3 outNormal;
layout(location = 2) flat out uint outMaterial;
layout(location = 3) flat out vec3 outAlbedo;
layout(location = 4) flat out vec3 outEmission;

void main()
{
    const vec3 relative = inPosition - frame.cameraPosition.xyz;
    outRelative = relative;
    outNormal = inNormal;
    outMaterial = inMaterial;
    outAlbedo = inAlbedo;
    outEmission = inEmission;
    gl_Position = frame.relativeViewProjection * vec4(relative, 1.0);
}
