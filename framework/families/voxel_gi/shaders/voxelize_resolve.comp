#version 450
// Voxelization on Vulkan, step 2 of 2: per voxel, the three axes' sums of voxelize_columns.comp
// turned into the volumetric G-buffer: per face occupancy (the share of the axis' rays covering
// the voxel) and the mean albedo and emission of the surfaces those rays met (the voxel's mean
// surface for rays that only run through its solid part), the mean normal, and the flags
// (surface; solid when the centre lies inside closed spans along two axes). The same as the end
// of voxelgi::voxelizeTriangles (framework/families/voxel_gi/voxelize.cpp).

layout(local_size_x = 64, local_size_y = 1, local_size_z = 1) in;

layout(std430, binding = 0) readonly buffer CountBuffer { uint counts[]; };
layout(std430, binding = 1) readonly buffer FaceBuffer { vec4 faceSums[]; };
layout(std430, binding = 2) readonly buffer NormalBuffer { vec4 normalSums[]; };
layout(std430, binding = 3) writeonly buffer FacesOut { vec4 faces[]; };     // [voxel * 6 + face]: albedo, occupancy
layout(std430, binding = 4) writeonly buffer EmissionOut { vec4 emission[]; }; // [voxel * 6 + face]
layout(std430, binding = 5) writeonly buffer NormalOut { vec4 normals[]; };   // [voxel]: normal, w: flags

layout(push_constant) uniform Constants {
    ivec4 size; // resolution R, supersampling S
} pc;

void main()
{
    const int R = pc.size.x;
    const uint voxel = gl_GlobalInvocationID.x;
    if (voxel >= uint(R * R * R))
        return;
    bool surface = false;
    vec3 meanAlbedo = vec3(0.0), meanEmission = vec3(0.0);
    float meanCount = 0.0;
    for (int a = 0; a < 3; ++a) {
        const uint n = counts[(voxel * 3u + uint(a)) * 3u + 1u];
        if (n > 0u) {
            surface = true;
            for (int face = 2 * a; face <= 2 * a + 1; ++face) {
                meanAlbedo += faceSums[(voxel * 6u + uint(face)) * 2u].rgb;
                meanEmission += faceSums[(voxel * 6u + uint(face)) * 2u + 1u].rgb;
                meanCount += float(n);
            }
        }
    }
    const float raysPerColumn = float(pc.size.y * pc.size.y);
    for (int face = 0; face < 6; ++face) {
        faces[voxel * 6u + uint(face)] = vec4(0.0);
        emission[voxel * 6u + uint(face)] = vec4(0.0);
    }
    for (int a = 0; a < 3; ++a) {
        const uint n = counts[(voxel * 3u + uint(a)) * 3u];
        if (n == 0u || !surface)
            continue;
        const uint m = counts[(voxel * 3u + uint(a)) * 3u + 1u];
        const float occupancy = min(1.0, float(n) / raysPerColumn);
        for (int face = 2 * a; face <= 2 * a + 1; ++face) {
            const uint i = voxel * 6u + uint(face);
            const vec3 albedo = m > 0u ? faceSums[i * 2u].rgb / float(m) : meanAlbedo / meanCount;
            const vec3 e = m > 0u ? faceSums[i * 2u + 1u].rgb / float(m) : meanEmission / meanCount;
            faces[i] = vec4(albedo, occupancy);
            emission[i] = vec4(e, 0.0);
        }
    }
    float flags = 0.0;
    vec3 normal = vec3(0.0);
    if (surface) {
        flags = 1.0;
        const vec3 sum = normalSums[voxel * 3u].xyz + normalSums[voxel * 3u + 1u].xyz +
                         normalSums[voxel * 3u + 2u].xyz;
        const float len = length(sum);
        if (len > 1e-9)
            normal = sum / len;
    } else {
        const uint votes = counts[voxel * 9u + 2u] + counts[voxel * 9u + 5u] + counts[voxel * 9u + 8u];
        if (votes >= 2u)
            flags = 2.0;
    }
    normals[voxel] = vec4(normal, flags);
}
