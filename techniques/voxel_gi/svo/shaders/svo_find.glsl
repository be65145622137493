// The sparse voxel octree's lookup on Vulkan (sparse_voxel_octree.h OctreeTopology::find): a
// descent from the root through the child pointers (Crassin et al. 2011, the node pool). The
// includer declares uint children[]: [node] = the first of its 8 children, 0 = none.

// The node of voxel c at `level`, or -1 (outside the lattice or an empty region).
int findNode(int level, ivec3 c)
{
    if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, ivec3(1 << level))))
        return -1;
    uint node = 0u;
    for (int k = level - 1; k >= 0; --k) {
        const uint child = children[node];
        if (child == 0u)
            return -1;
        node = child + uint(((c.x >> k) & 1) | (((c.y >> k) & 1) << 1) | (((c.z >> k) & 1) << 2));
    }
    return int(node);
}
