#version 450
// G-buffer pass, fragment stage. Everything is evaluated at the pixel's sample position (the
// pixel centre moved by the jitter that the projection carries).

#include "gbuffer_frame.glsl"

layout(location = 0) in vec3 inRelative;
layout(location = 1) in vec3 inNormal;
layout(location = 2) flat in uint inMaterial;
layout(location = 3) flat in vec3 inAlbedo;
layout(location = 4) flat in vec3 inEmission;

layout(location = 0) out vec4 outPositionDepth; // xyz: world position, w: linear depth
layout(location = 1) out vec4 outNormal;        // xyz: unit shading normal facing the viewer
layout(location = 2) out vec4 outAlbedo;        // rgb
layout(location = 3) out vec4 outEmission;      // rgb
layout(location = 4) out uint outMaterial;

void main()
{
    const float depth = dot(inRelative, frame.viewForward.xyz);

    // Interpolated shading normal, turned to the side of the surface that faces the camera:
    // a triangle seen from its back (clockwise on screen) gets its normals negated.
    vec3 normal = inNormal;
    const float len = length(normal);
    if (len > 0.0) {
        normal /= len;
        if (!gl_FrontFacing)
            normal = -normal;
    } else {
        // No usable shading normal: the geometric normal, facing the camera.
        normal = normalize(cross(dFdx(inRelative), dFdy(inRelative)));
        if (dot(normal, inRelative) > 0.0)
            normal = -normal;
    }

    outPositionDepth = vec4(frame.cameraPosition.xyz + inRelative, depth);
    outNormal = vec4(normal, 0.0);
    outAlbedo = vec4(inAlbedo, 1.0);
    outEmission = vec4(inEmission, 1.0);
    outMaterial = inMaterial;
}
