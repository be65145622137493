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

    // The geometric normal (the triangle's plane: the derivatives of one primitive's position),
    // facing the camera.
    const vec3 edge = cross(dFdx(inRelative), dFdy(inRelative));
    const float edgeLength = length(edge);
    vec3 geometric = edgeLength > 0.0 ? edge / edgeLength : vec3(0.0);
    if (dot(geometric, inRelative) > 0.0)
        geometric = -geometric;
    // Interpolated shading normal, turned to the side of the surface that faces the camera:
    // a triangle seen from its back (clockwise on screen) gets its normals negated, and a
    // shading normal that still points into the surface (vertex normals averaged across faces
    // wound against each other) is turned to the geometric normal's side, as the Embree
    // G-buffer does (reference/primary_rays.cpp), so no hemisphere lies inside the surface.
    vec3 normal = inNormal;
    const float len = length(normal);
    if (len > 0.0) {
        normal /= len;
        if (!gl_FrontFacing)
            normal = -normal;
        if (dot(normal, geometric) < 0.0)
            normal = -normal;
    } else {
        // No usable shading normal: the geometric normal.
        normal = geometric;
    }

    outPositionDepth = vec4(frame.cameraPosition.xyz + inRelative, depth);
    outNormal = vec4(normal, 0.0);
    outAlbedo = vec4(inAlbedo, 1.0);
    outEmission = vec4(inEmission, 1.0);
    outMaterial = inMaterial;
}
