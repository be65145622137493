#pragma once
// Validated inputs of one reference computation (internal to rtlab_reference): the Embree scene,
// the light tables, the surface points of the G-buffer and the per-sample function.

#include "reference/integrators.h"
#include "reference/progressive.h"

#include <cstdint>
#include <vector>

namespace rtlab::reference {

//! Throws rtlab::Error naming the first bad setting.
void validateSettings(const ReferenceSettings& settings);
//! Throws rtlab::Error when an image does not match the G-buffer's size or a surface pixel has
//! a non-finite position or a zero normal.
void validateGBuffer(const scene::GBuffer& gbuffer);

class PreparedReference {
public:
    //! Validates everything and builds the Embree scene (call inside the task arena).
    PreparedReference(const scene::RenderScene& scene, const scene::GBuffer& gbuffer,
                      const ReferenceSettings& settings);

    //! Sample `index` of pixel `pixel`; the pixel must be active.
    std::uint32_t evaluate(std::size_t pixel, std::uint32_t index, SampleValue& value) const;
    //! Samples first .. first + count - 1 of a pixel (progressive.h BatchSampleFunction).
    std::uint32_t evaluateBatch(std::size_t pixel, std::uint32_t first, std::uint32_t count,
                                SampleValue* values) const;

    const EmbreeScene& getEmbree() const { return mEmbree; }
    const TraceContext& getContext() const { return mContext; }
    const std::vector<std::uint8_t>& getActive() const { return mActive; }
    const SurfacePoint& getPoint(std::size_t pixel) const { return mPoints[pixel]; }

private:
    ReferenceSettings mSettings;
    EmbreeScene mEmbree;
    SceneLights mLights;
    TraceContext mContext;
    std::vector<std::uint8_t> mActive;
    std::vector<SurfacePoint> mPoints;
};

} // namespace rtlab::reference
