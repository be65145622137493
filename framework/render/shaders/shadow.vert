#version 450
// Cube shadow map, vertex stage: positions relative to the light, projected onto one cube face
// (render/shadow_pass.h).

layout(push_constant) uniform ShadowFace {
    mat4 relativeFaceProjection; // (p - light) -> clip space of the face
    vec4 lightPosition;          // xyz: world units
} face;

layout(location = 0) in vec3 inPosition; // world units

layout(location = 0) out vec3 outRelative; // world position - light position

void main()
{
    const vec3 relative = inPosition - face.lightPosition.xyz;
    outRelative = relative;
    gl_Position = face.relativeFaceProjection * vec4(relative, 1.0);
}
