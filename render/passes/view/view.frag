#version 450 core
#include "common.glsl"
#include "passes/view/view_units.glsl"
// The resource view (ResourceViewPass.h): one of the frame's textures in place of the composite,
// stretched over the camera image, scaled, a single-channel texture shown grey.
in vec2 uv;
#ifdef MIRAGE_VIEW_ARRAY
layout(binding = kUnitViewSource) uniform sampler2DArray source;
#else
layout(binding = kUnitViewSource) uniform sampler2D source;
#endif
uniform float scale;       // multiplies the texels (depths in metres, small radiances)
uniform int layer;         // the array layer shown
uniform int singleChannel; // 1: show r as grey
layout(location = 0) out vec4 linearOut;
layout(location = 1) out vec4 srgbOut;  // GL_FRAMEBUFFER_SRGB encodes it

void main() {
#ifdef MIRAGE_VIEW_ARRAY
    vec4 t = texture(source, vec3(uv, float(layer)));
#else
    vec4 t = texture(source, uv);
#endif
    vec3 c = (singleChannel != 0 ? vec3(t.r) : t.rgb) * scale;
    // NaN and negative texels (signed buffers) show black: the view is for looking, not for
    // measuring (the readback is: Renderer::readBuffer).
    c = clamp(c, vec3(0.0), vec3(65504.0));
    c = mix(c, vec3(0.0), isnan(c));
    linearOut = vec4(c, 1.0);
    srgbOut = vec4(clamp(c, vec3(0.0), vec3(1.0)), 1.0);
}
