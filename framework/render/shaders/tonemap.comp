#version 450
// Exposure, tonemapper and sRGB encoding of an HDR image (render/lighting_pass.h; the CPU twin
// is computeTonemappedColor).

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D inHdr;
layout(binding = 1, rgba8) uniform writeonly image2D outLdr;

layout(push_constant) uniform Tonemap {
    float exposureScale; // 2^ev
    uint tonemapper;     // 0 ACES (Narkowicz 2015), 1 Reinhard per channel
    uint width;
    uint height;
} params;

// IEC 61966-2-1.
float encodeSrgb(float x)
{
    return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

void main()
{
    const ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(params.width) || pixel.y >= int(params.height))
        return;
    const vec3 hdr = imageLoad(inHdr, pixel).rgb * params.exposureScale;
    vec3 ldr;
    for (int c = 0; c < 3; ++c) {
        const float x = hdr[c] > 0.0 ? hdr[c] : 0.0; // negative and NaN -> 0
        float y;
        if (params.tonemapper == 0u)
            // ACES filmic fit [Narkowicz 2015, "ACES Filmic Tone Mapping Curve"].
            y = (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14);
        else
            // [Reinhard et al. 2002] x / (1 + x), per channel.
            y = x / (1.0 + x);
        ldr[c] = encodeSrgb(clamp(y, 0.0, 1.0));
    }
    imageStore(outLdr, pixel, vec4(ldr, 1.0));
}
