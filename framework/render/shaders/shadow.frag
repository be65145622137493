#version 450
// Cube shadow map, fragment stage: the Euclidean distance from the light to the surface at the
// texel's centre (the relative position is interpolated perspective-correctly, which is exact on
// a planar triangle). The depth test keeps the nearest surface.

layout(location = 0) in vec3 inRelative;

layout(location = 0) out float outDistance; // world units

void main()
{
    outDistance = length(inRelative);
}
