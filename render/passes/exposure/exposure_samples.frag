#version 450 core
#include "common.glsl"
// One sample block of the exposure measurement per output pixel (passes/exposure/ExposurePass.h):
// the block's taps x taps canvas pixels, `stride` apart, must all show a REAL surface that is not
// a mirror or glass (the G-buffer is the mixed scene's: a virtual object in front hides it), seen
// by a camera pixel whose footage is neither clipped at black (code 0) nor near white (code 250
// and above) in any channel, and the rendered L_r must be smooth over the block (max / min
// luminance within maxVariation: a block on an edge of the model is moved by any pose error).
// Output: the block's mean footage and mean L_r (linear; L_r before exposure, caustic light
// included), and the standard error of the footage's mean luminance over that mean (noise).
in vec2 uv;
layout(binding = kUnitExposureCamera) uniform sampler2D cameraImage;  // sRGB8: samples linear
layout(binding = kUnitExposureLR) uniform sampler2D lR;               // canvas, linear
layout(binding = kUnitExposureCausticR) uniform sampler2D causticR;   // canvas, linear
layout(binding = kUnitExposurePosition) uniform sampler2D gPosition;  // canvas, w = origin
layout(binding = kUnitExposureEmissive) uniform sampler2D gEmissive;  // canvas, a = slot + 1
layout(binding = kUnitExposureCanvasToCamera) uniform sampler2D canvasToCamera;  // camera pixel
uniform int blockSize;       // canvas pixels per side of a block
uniform int taps;            // taps per side
uniform int stride;          // canvas pixels between taps
uniform int withCaustics;    // 1: the caustic pass ran (causticR holds real caustic light)
uniform float maxVariation;  // of L_r's luminance over the block
layout(location = 0) out vec4 outFootage;   // rgb mean footage (linear), a = 1 usable block
layout(location = 1) out vec4 outRendered;  // rgb mean L_r (linear), a = relative std error

const float kBlackLinear = 0.5 / 255.0 / 12.92;  // below half a code: clipped at black
const float kWhiteLinear = 0.9560;               // sRGB code 250: clipping near

float lum(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

void main() {
    ivec2 block = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(lR, 0);
    ivec2 camSize = textureSize(cameraImage, 0);
    ivec2 first = block * blockSize + (blockSize - (taps - 1) * stride) / 2;
    vec3 sumCi = vec3(0.0), sumR = vec3(0.0);
    float sumLum2 = 0.0, minR = 1e30, maxR = 0.0;
    bool usable = true;
    for (int j = 0; j < taps && usable; ++j)
        for (int i = 0; i < taps && usable; ++i) {
            ivec2 p = first + ivec2(i, j) * stride;
            if (any(greaterThanEqual(p, size))) {
                usable = false;
                break;
            }
            int origin = int(texelFetch(gPosition, p, 0).w + 0.5);
            bool specular = texelFetch(gEmissive, p, 0).a > 0.5;
            vec2 q = texelFetch(canvasToCamera, p, 0).xy;
            ivec2 qi = ivec2(floor(q + 0.5));
            if (origin != ORIGIN_REAL || specular || q.x < -1000.0 || any(lessThan(qi, ivec2(0))) ||
                any(greaterThanEqual(qi, camSize))) {
                usable = false;
                break;
            }
            vec3 ci = texelFetch(cameraImage, qi, 0).rgb;  // both top row first (CameraProjection.h)
            vec3 r = texelFetch(lR, p, 0).rgb;
            if (withCaustics != 0) r += texelFetch(causticR, p, 0).rgb;
            if (any(lessThanEqual(ci, vec3(kBlackLinear))) ||
                any(greaterThanEqual(ci, vec3(kWhiteLinear))) || !allFinite(r)) {
                usable = false;
                break;
            }
            float l = lum(r);
            minR = min(minR, l);
            maxR = max(maxR, l);
            sumCi += ci;
            sumR += r;
            sumLum2 += lum(ci) * lum(ci);
        }
    float n = float(taps * taps);
    usable = usable && minR > 0.0 && maxR <= maxVariation * minR;
    vec3 meanCi = sumCi / n;
    float meanLum = lum(meanCi);
    float variance = max(sumLum2 / n - meanLum * meanLum, 0.0);
    float relativeError = meanLum > 0.0 ? sqrt(variance / max(n - 1.0, 1.0)) / meanLum : 1e30;
    outFootage = vec4(meanCi, usable ? 1.0 : 0.0);
    outRendered = vec4(sumR / n, relativeError);
}
