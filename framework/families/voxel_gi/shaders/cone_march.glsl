// The front-to-back march of one cone, shared by the Vulkan gathers (svo_gather.comp,
// tree_cone_gather.comp, cascade_gather.comp): voxelgi::marchCone (cone_tracing.h) in float, the
// reflected light and, when asked, the sky's own transmittance and the emitters the cone meets
// (the Tomorrow Children's sky through the cones, shared/seeds/000_3da000e866ebc485.txt, "Sky
// Light"). The including shader defines, before the #include,
//   bool sampleCone(vec3 q, float diameter, vec3 dir, int cone, bool wantsDepth, bool wantsEmission,
//                   out vec4 s, out vec3 emission, out float depth, out float voxelSize)
// which returns false when q is outside the structure, else the filtered sample at q for a
// footprint `diameter` wide: s.rgb the gathered light premultiplied by the occupancy s.a,
// `emission` the emitted radiance premultiplied the same way (when wantsEmission), `depth` the
// same voxels' optical depths with the same weights (when wantsDepth; cone_tracing.h
// ConeSample::depth) and `voxelSize` the size of the voxels sampled.

struct ConeMarch {
    float t0;           // world units along the cone before the first sample
    float tMax;         // and where it stops (a split cone's near part)
    float tanHalfAngle; // of the cone
    float stepScale;    // step = stepScale * size of the voxels sampled
    int maxSteps;
    bool sky;           // march the sky's transmittance too, and the emitters
    bool opticalDepth;  // the sky's transmittance in optical depth (else occupancy)
    float skyStart;     // world units along the cone from which the voxels hide the sky
    vec3 planeNormal;   // the surface the cone leaves (0: none), and the origin's height above it
    float planeHeight;
};

struct ConeTrace {
    vec3 light;             // the gathered light seen along the cone
    vec3 emission;          // the emitters seen along it (ConeMarch.sky)
    float transmittance;    // 1 - the occupancy accumulated for the light
    float skyTransmittance; // what the voxels from skyStart on let through to the sky
    bool escaped;           // left the structure while the light was not done
    bool skyEscaped;        // left it (marching on for the sky once the light was done)
};

// An opaque voxel's optical depth, -ln(1e-4) (cone_tracing.h kOpaqueOpticalDepth).
const float kOpaqueOpticalDepth = 9.2103404;

ConeTrace marchCone(vec3 origin, vec3 dir, int cone, ConeMarch m)
{
    ConeTrace r;
    r.light = vec3(0.0);
    r.emission = vec3(0.0);
    r.escaped = false;
    r.skyEscaped = false;
    const bool plane = dot(m.planeNormal, m.planeNormal) > 0.0;
    float occupied = 0.0;
    float skyDepth = 0.0;
    // The sky is hidden when its transmittance is as low as the light's limit, -ln(1 - 0.99).
    const float skyHidden = 4.6051702;
    bool lightDone = false;
    float t = m.t0;
    for (int step = 0; step < m.maxSteps; ++step) {
        if (t >= m.tMax)
            break;
        const float diameter = 2.0 * t * m.tanHalfAngle;
        const vec3 q = origin + t * dir;
        vec4 s;
        vec3 emission;
        float depth, voxelSize;
        // At or past the sky's start, with cone_tracing.h isPastSkyStart's margin.
        const bool pastSkyStart = t >= m.skyStart * (1.0 - 1e-4);
        if (!sampleCone(q, diameter, dir, cone, m.sky && m.opticalDepth && pastSkyStart, m.sky && !lightDone, s,
                        emission, depth, voxelSize)) {
            r.escaped = !lightDone;
            r.skyEscaped = true;
            break;
        }
        const float dt = m.stepScale * voxelSize;
        const float a = clamp(s.a, 0.0, 1.0);
        if (a > 0.0) {
            // Opacity corrected for the step, a' = 1 - (1 - a)^(dt / voxelSize).
            const float corrected = 1.0 - pow(1.0 - min(a, 0.999999), dt / voxelSize);
            if (!lightDone) {
                const float weight = (1.0 - occupied) * corrected / a;
                r.light += weight * s.rgb;
                if (m.sky)
                    r.emission += weight * emission;
                occupied += (1.0 - occupied) * corrected;
                lightDone = occupied >= 0.99;
            }
            if (m.sky && pastSkyStart) {
                // The part of the sample below the surface the cone leaves is taken out
                // (cone_tracing.h marchCone: the degree-1 B-spline of the solid half-space).
                float below = 0.0;
                if (plane) {
                    const float h = m.planeHeight + t * dot(dir, m.planeNormal);
                    const float u = clamp(h / voxelSize, -1.0, 1.0);
                    below = u >= 0.0 ? 0.5 * (1.0 - u) * (1.0 - u) : 1.0 - 0.5 * (1.0 + u) * (1.0 + u);
                }
                float skyDepthHere = max(0.0, (m.opticalDepth ? depth : 0.0) - below * kOpaqueOpticalDepth);
                if (!m.opticalDepth) {
                    const float skyAlpha = below < 1.0 ? max(0.0, a - below) / (1.0 - below) : 0.0;
                    skyDepthHere = -log(1.0 - min(skyAlpha, 0.999999));
                }
                skyDepth += skyDepthHere * (dt / voxelSize);
            }
            if (lightDone && (!m.sky || skyDepth >= skyHidden))
                break;
        }
        t += dt;
    }
    r.transmittance = 1.0 - occupied;
    r.skyTransmittance = m.sky ? exp(-skyDepth) : r.transmittance;
    return r;
}

// What the cone gives the lit frame's sky: the emitters it met, plus the sky where it left the
// structure times what the voxels let through (cone_tracing.h computeConeSkyRadiance).
vec3 getConeSkyRadiance(ConeTrace r, vec3 skyOfCone)
{
    vec3 sky = r.emission;
    if (r.skyEscaped)
        sky += r.skyTransmittance * skyOfCone;
    return max(sky, vec3(0.0));
}
