#pragma once
// A registry with the built-in families and one fake technique per family, so framework tests do
// not depend on which real techniques are compiled in.

#include "families/isosurface/isosurface.h"
#include "plugin/technique.h"

namespace rtlab::test {

//! isosurface/fake_mesher: resolution int [1, 64] = 8, mode enum {fast, exact} = fast,
//! scale float [0, 10] = 1, smooth bool = false. It emits one triangle per 'resolution'.
class FakeMesher final : public plugin::IsosurfaceTechnique {
public:
    static plugin::TechniqueInfo describe() { return {.summary = "test double"}; }
    static config::ParamSchema declareParams()
    {
        config::ParamSchema s;
        s.addInt("resolution", 8, 1, 64, "cells", "test knob");
        s.addEnum("mode", "fast", {"fast", "exact"}, "test enum");
        s.addFloat("scale", 1.0, 0.0, 10.0, "world units", "test float");
        s.addBool("smooth", false, "test bool");
        return s;
    }
    explicit FakeMesher(const config::ParamSet& p) : mParams(p) {}
    config::ParamSet effectiveParams() const override { return mParams; }
    void extract(const plugin::IsosurfaceInput&, TriangleMesh& out) override
    {
        out.clear();
        for (std::int64_t i = 0; i < mParams.getInt("resolution"); ++i) {
            const auto base = std::uint32_t(out.positions.size());
            out.positions.insert(out.positions.end(), {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
            out.indices.insert(out.indices.end(), {base, base + 1, base + 2});
        }
    }

private:
    config::ParamSet mParams;
};

inline plugin::Registry makeTestRegistry()
{
    plugin::Registry r;
    plugin::registerBuiltinFamilies(r);
    plugin::registerTechnique<FakeMesher>(r, "isosurface", "fake_mesher");
    return r;
}

} // namespace rtlab::test
