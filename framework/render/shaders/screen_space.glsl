// Screen-space geometry shared by screen-space techniques: the GLSL twin of
// framework/plugin/screen_space.h (same conventions, same formulas).
//   projScale  = (p[0][0], p[1][1]) of the projection matrix
//   projOffset = (p[2][0], p[2][1]) (jitter)
//   size       = image size in pixels
#ifndef RTLAB_SCREEN_SPACE_GLSL
#define RTLAB_SCREEN_SPACE_GLSL

vec3 screenToView(vec2 pixel, float depth, vec2 projScale, vec2 projOffset, vec2 size)
{
    vec2 ndc = 2.0 * pixel / size - 1.0;
    return vec3(depth * (ndc + projOffset) / projScale, -depth);
}

vec2 viewToScreen(vec3 p, vec2 projScale, vec2 projOffset, vec2 size)
{
    float depth = -p.z;
    vec2 ndc = p.xy * projScale / depth - projOffset;
    return (ndc + 1.0) * 0.5 * size;
}

float worldToPixelLength(float worldLength, float depth, vec2 projScale, vec2 size)
{
    return worldLength * projScale.x * 0.5 * size.x / depth;
}

#endif
