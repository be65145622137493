#pragma once
// Screen-space ground truth: the occlusion quantities of reference.h (ao, ao_uniform, obscurance,
// bent) computed from one view's depth buffer alone, by tracing the very hemisphere rays of the
// Embree reference against the depth buffer taken as a height field. A technique's error then
// splits into its estimator error (technique vs this) and what screen space cannot see (this vs
// computeReference on the full scene).
//
// Conventions (besides these, every definition, sample and output is that of reference.h):
//  * Surface. Each pixel's footprint [x, x+1) x [y, y+1) holds a planar facet through its
//    sample point (pixel centre + jitter, as ScreenProjection places it): its inverse linear
//    depth w = 1/d is affine in the pixel position (every plane is, under perspective). The
//    facet's slope per axis is the one-sided difference of w toward the neighbour closest to the
//    plane of the pixel's normal, or that plane itself when both differences jump by more than
//    a tenth of the pixel's w (a silhouette) or no neighbour has a surface; without a normal,
//    the smaller difference. Planes are thus reconstructed exactly, creases keep each side's
//    plane up to the pixel the crease runs through, and silhouettes are steps, not skins.
//    Sky (depth inf, NaN or <= 0) has w = 0: infinitely far, it never occludes.
//  * Thickness. A ray point at linear depth z above reconstructed surface depth z_s is occluded
//    when z > z_s (1 + depthBias) and z < z_s + thickness. The default thickness is infinite:
//    everything behind the visible surface is solid, the assumption screen-space methods make.
//    depthBias (relative, default 1e-4) keeps float noise of the depth buffer from occluding rays
//    that graze their own plane; it delays a hit by at most depthBias * z_s in depth.
//  * Rays. Origins are the pixels' own surface points (no offset: on the reconstructed surface a
//    ray of the hemisphere starts in front of it); distances are measured from there. Directions
//    are those of the Embree reference for the same seed and pixel: the same scrambled Sobol
//    sequence (sequences.h), the same frame around the world-space normal view^-1 n, then taken
//    to view space, so that the two ground truths use common random numbers.
//  * Traversal. Exact: with sigma = t / d(t) (t = distance along the ray, d(t) its linear depth)
//    the ray's pixel position and its w are affine in sigma, so the ray is a straight line over
//    the pixel grid, walked pixel by pixel [Amanatides & Woo 1987]; over each pixel the occlusion
//    conditions are polynomials in sigma of degree 1 (infinite thickness) or 2 (finite
//    thickness), whose first positive interval is found from their roots. There is no step
//    length and no sampling bias along the ray: every pixel the ray crosses is tested.
//  * Leaving the view. A ray that leaves the image ([0, width] x [0, height] in pixels) before the
//    radius, or that comes nearer to the camera than every visible surface while approaching it,
//    counts as unoccluded; the share of rays leaving the image is reported per pixel.
//  * Pixels. A pixel with a finite depth but a zero or non-finite normal occludes others but gets
//    the no-surface values of reference.h (occlusion 1, bent (0, 0, 0), apertures 0, 0 samples).
//  * Radius. radius = 0 is allowed here: nothing lies within distance 0, every quantity is 1.
//  * Output. A ReferenceResult exactly like computeReference's (bent normals in world space via
//    view^-1, standard errors, sample counts), computed by the same progressive stopping rule
//    with the same settings; images are bitwise identical for any thread count. The cache, ray
//    epsilon and bounce settings do not apply. stats.rayEpsilon and stats.sceneScale are 0.

#include "core/image.h"
#include "reference/reference.h"

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <cstdint>
#include <limits>

namespace rtlab::reference {

//! One view of a G-buffer (the fields of plugin::OcclusionInput that screen space sees).
struct ScreenSpaceView {
    const Image<float>* linearDepth = nullptr; //!< view-space distance along -z; inf = sky
    const Image<glm::vec3>* normal = nullptr;  //!< view-space unit normals; zero where no surface
    glm::mat4 projection{1.0f}; //!< view -> Vulkan clip space (perspective), jitter included
    glm::mat4 view{1.0f};       //!< world -> view (rigid); identity keeps everything in view space
};

struct ScreenSpaceOptions {
    //! Depth extent of the solid behind the visible surface, world units along the view axis,
    //! > 0; infinity = everything behind the visible surface is solid.
    double thickness = std::numeric_limits<double>::infinity();
    //! A ray point must lie behind the surface by more than depthBias * its depth, [0, 0.1].
    double depthBias = 1e-4;
};

struct ScreenSpaceResult {
    //! The quantity of settings.quantity, in the layout and conventions of computeReference.
    ReferenceResult reference;
    //! Per pixel: share of the traced rays that left the image unoccluded within the radius
    //! (0 where no surface).
    Image<float> offScreenShare;
    double meanOffScreenShare = 0.0; //!< over surface pixels
    std::uint64_t cellsVisited = 0;  //!< pixels walked, all rays together
};

//! The screen-space ground truth of settings.quantity (ao, ao_uniform, obscurance or bent; the
//! light quantities throw). Throws rtlab::Error for missing or mismatched images, an empty
//! image, bad settings or options.
ScreenSpaceResult computeScreenSpaceReference(const ScreenSpaceView& view,
                                              const ReferenceSettings& settings,
                                              const ScreenSpaceOptions& options = {});

} // namespace rtlab::reference
