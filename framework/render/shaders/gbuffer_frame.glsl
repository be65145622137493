// Per-frame constants of the G-buffer pass, shared by gbuffer.vert and gbuffer.frag.
// Mirrors render::GBufferFrameConstants (96 bytes).

layout(push_constant) uniform GBufferFrame {
    // Camera-relative world -> clip: projection * view rotation, applied to (p - cameraPosition).
    mat4 relativeViewProjection;
    vec4 cameraPosition; // xyz: world units
    vec4 viewForward;    // xyz: unit view direction (view-space -z) in world space
} frame;
