// The adaptive voxel tree's lookup on Vulkan (voxel_tree.h AdaptiveVoxelTree::find): a descent
// from the element's dense root cell, below the roots an element's node record found by rank;
// the child index is Quantum Break's offset + popcount of the mask bits below the child's
// (Silvennoinen & Timonen, SIGGRAPH 2015, "Adaptive Voxel Tree"), the 64-bit popcount as two
// 32-bit bitCounts. The includer declares the topology buffer, uint topology[]: the rank words
// ([word * 3 + 0, 1, 2]: which of 64 upper-level elements have a record, low and high 32 bits,
// and how many before the word do), then the node records as the tree holds them (see
// tree_cone_gather.comp).

// The element at cell c of `level`, or -1 (outside the lattice or an empty region). roots: xyz
// root cells per axis, w the first node record's uint in topology[]; masks: x the shared
// masks' record bits (0: inline), y the first base's uint, z the mask table's first uint.
int findTreeElement(int level, ivec3 c, ivec4 roots, ivec4 masks)
{
    const int shift = 2 * level;
    if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c >> shift, roots.xyz)))
        return -1;
    const ivec3 r = c >> shift;
    uint index = uint(r.x + roots.x * (r.y + roots.y * r.z));
    uint record = index; // the dense first level: every root cell has a node record
    for (int s = shift - 2; s >= 0; s -= 2) {
        uint lo, hi, offset;
        if (masks.x == 0) {
            const uint at = uint(roots.w) + 3u * record;
            lo = topology[at];
            hi = topology[at + 1u];
            offset = topology[at + 2u];
        } else {
            // The record's field may straddle two words (the last has a padding word after it).
            const uint width = uint(masks.x), bit = record * width;
            const uint first = uint(roots.w) + (bit >> 5u), shift = bit & 31u;
            uint word = topology[first] >> shift;
            if (shift + width > 32u)
                word |= topology[first + 1u] << (32u - shift);
            word &= width >= 32u ? 0xffffffffu : (1u << width) - 1u;
            const uint at = uint(masks.z) + 2u * (word >> 12u);
            lo = topology[at];
            hi = topology[at + 1u];
            offset = topology[uint(masks.y) + (record >> 6u)] + (word & 4095u);
        }
        const int bit = ((c.x >> s) & 3) | (((c.y >> s) & 3) << 2) | (((c.z >> s) & 3) << 4);
        uint below;
        if (bit < 32) {
            if (((lo >> uint(bit)) & 1u) == 0u)
                return -1;
            below = uint(bitCount(lo & ((1u << uint(bit)) - 1u)));
        } else {
            const uint b = uint(bit - 32);
            if (((hi >> b) & 1u) == 0u)
                return -1;
            below = uint(bitCount(lo)) + uint(bitCount(hi & ((1u << b) - 1u)));
        }
        index = offset + below;
        if (s > 0) {
            // The child's node record by rank; an element without one has no children.
            const uint word = 3u * (index >> 6u), b = index & 63u;
            const uint rankLo = topology[word], rankHi = topology[word + 1u];
            record = topology[word + 2u];
            if (b < 32u) {
                if (((rankLo >> b) & 1u) == 0u)
                    return -1;
                record += uint(bitCount(rankLo & ((1u << b) - 1u)));
            } else {
                if (((rankHi >> (b - 32u)) & 1u) == 0u)
                    return -1;
                record += uint(bitCount(rankLo)) + uint(bitCount(rankHi & ((1u << (b - 32u)) - 1u)));
            }
        }
    }
    return int(index);
}
