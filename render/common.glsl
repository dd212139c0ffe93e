// Shared GPU code of the real-time renderer: the data layout (gpu_types.glsl, shared with C++),
// the binding points (bindings.glsl), and the light falloff / SH helpers. Frames: world = glTF
// (metres, +Y up); camera = OpenCV (+X right, +Y down, +Z forward). Every radiance value here is
// LINEAR RGB (W / (m^2 sr), with the scene's exposure convention that 1.0 is the camera's white).
#ifndef MIRAGE_COMMON_GLSL
#define MIRAGE_COMMON_GLSL

#include "gpu_types.glsl"

#define MAX_LIGHTS kMaxLights
#define LIGHT_POINT kLightPoint
#define LIGHT_SPOT kLightSpot
#define LIGHT_DIRECTIONAL kLightDirectional
#define ORIGIN_NONE kOriginNone
#define ORIGIN_REAL kOriginReal
#define ORIGIN_VIRTUAL kOriginVirtual
#define PI 3.14159265358979

// VPL i of the VPL buffer read through a buffer texture of RGBA32F texels, four per GpuVpl (its
// std430 layout: position | isReal, normal | valid, flux | pad, tangent | pad). llvmpipe reads a
// storage buffer lane by lane at a per-pixel index; a texel fetch is one gather.
GpuVpl vplAt(samplerBuffer texels, int i) {
    vec4 a = texelFetch(texels, 4 * i), b = texelFetch(texels, 4 * i + 1);
    vec4 c = texelFetch(texels, 4 * i + 2), d = texelFetch(texels, 4 * i + 3);
    GpuVpl V;
    V.position = a.xyz;
    V.isReal = floatBitsToInt(a.w);
    V.normal = b.xyz;
    V.valid = floatBitsToInt(b.w);
    V.flux = c.xyz;
    V.pad0 = 0.0;
    V.tangent = d.xyz;
    V.pad1 = 0.0;
    return V;
}

// Material i and specular draw i from their tables read as buffer textures of RGBA32F texels
// (GpuScene::bindTableTexels; the std430 layouts of gpu_types.glsl, 5 and 2 texels each).
GpuMaterial materialAt(samplerBuffer texels, int i) {
    vec4 a = texelFetch(texels, 5 * i), b = texelFetch(texels, 5 * i + 1);
    vec4 c = texelFetch(texels, 5 * i + 2), d = texelFetch(texels, 5 * i + 3);
    vec4 e = texelFetch(texels, 5 * i + 4);
    GpuMaterial m;
    m.baseColor = a;
    m.emissive = b.xyz;
    m.roughness = b.w;
    m.metallic = c.x;
    m.transmission = c.y;
    m.ior = c.z;
    m.attenuationDistance = c.w;
    m.attenuationColor = d.xyz;
    m.mirror = floatBitsToInt(d.w);
    m.thickness = e.x;
    m.specular = floatBitsToInt(e.y);
    m.translucent = floatBitsToInt(e.z);
    m.pad2 = 0.0;
    return m;
}
GpuSpecularDraw specularDrawAt(samplerBuffer texels, int i) {
    vec4 a = texelFetch(texels, 2 * i);
    ivec4 b = floatBitsToInt(texelFetch(texels, 2 * i + 1));
    GpuSpecularDraw d;
    d.centre = a.xyz;
    d.radius = a.w;
    d.material = b.x;
    d.origin = b.y;
    d.drawIndex = b.z;
    d.rough = b.w;
    return d;
}

// LRv.a of a pixel = its origin + kSeeThroughScale x the share of the footage behind it that a
// translucent object lets through (direct.frag, composite.frag): below 0.5, so the origin still
// rounds out of it.
const float kSeeThroughScale = 0.45;

// Paraboloid coordinates (unit disc) of unit direction w around a VPL's normal (z axis).
vec2 paraboloidUv(GpuVpl V, vec3 w) {
    vec3 b = cross(V.normal, V.tangent);
    return vec2(dot(w, V.tangent), dot(w, b)) / (1.0 + dot(w, V.normal));
}

// Distance (m) of the nearest splatted point in direction puv (paraboloidUv) from VPL vplIndex
// in an imperfect shadow map atlas, +inf if none.
float ismDistance(usampler2D atlas, int vplIndex, vec2 puv) {
    int tile = ismTileSize, perRow = ismTilesPerRow;
    ivec2 texel = clamp(ivec2((puv * 0.5 + 0.5) * float(tile)), ivec2(0), ivec2(tile - 1));
    ivec2 origin = ivec2(vplIndex % perRow, vplIndex / perRow) * tile;
    return uintBitsToFloat(texelFetch(atlas, origin + texel, 0).r);
}

// glTF KHR_lights_punctual spot cone and range window (the spec's recommended falloff).
// Lights are passed by index, never copied: a GpuLight is 480 bytes and llvmpipe copies it per
// pixel if a shader takes it by value.
float spotAttenuation(int li, vec3 lightToPoint) {
    if (lights[li].type != LIGHT_SPOT) return 1.0;
    float cd = dot(lights[li].direction, lightToPoint);
    float a = clamp(cd * lights[li].coneScale + lights[li].coneOffset, 0.0, 1.0);
    return a * a;
}
float rangeWindow(int li, float dist) {
    float range = lights[li].range;
    if (range <= 0.0) return 1.0;
    float r = dist / range;
    return clamp(1.0 - r * r * r * r, 0.0, 1.0);
}

// Irradiance (W/m^2) from 9 SH coefficients of radiance for normal n (Ramamoorthi & Hanrahan).
vec3 shIrradiance(vec3 n) {
    const float c1 = 0.429043, c2 = 0.511664, c3 = 0.743125, c4 = 0.886227, c5 = 0.247708;
    vec3 e = c4 * envSH[0].rgb + 2.0 * c2 * (envSH[3].rgb * n.x + envSH[1].rgb * n.y +
                                             envSH[2].rgb * n.z) +
             c3 * envSH[6].rgb * n.z * n.z - c5 * envSH[6].rgb +
             c1 * envSH[8].rgb * (n.x * n.x - n.y * n.y) +
             2.0 * c1 * (envSH[4].rgb * n.x * n.y + envSH[5].rgb * n.y * n.z +
                         envSH[7].rgb * n.x * n.z);
    return max(e, vec3(0.0));
}

bool allFinite(vec3 v) { return !any(isnan(v)) && !any(isinf(v)); }

// Octahedral encoding of a unit vector into 2 x 16-bit snorm (Cigolle et al. 2014).
vec2 octEncode(vec3 n) {
    n /= max(abs(n.x) + abs(n.y) + abs(n.z), 1e-20);
    return n.z >= 0.0 ? n.xy : (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0,
                                                     n.y >= 0.0 ? 1.0 : -1.0);
}
vec3 octDecode(vec2 e) {
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    float t = max(-n.z, 0.0);
    n.xy += vec2(n.x >= 0.0 ? -t : t, n.y >= 0.0 ? -t : t);
    return normalize(n);
}
int packNormalOct(vec3 n) { return int(packSnorm2x16(octEncode(n))); }
vec3 unpackNormalOct(int bits) { return octDecode(unpackSnorm2x16(uint(bits))); }
// 16 bits (two 8-bit snorms, the low half of the result): about 1 degree at worst.
uint packNormalOct8(vec3 n) { return packSnorm4x8(vec4(octEncode(n), 0.0, 0.0)) & 0xFFFFu; }
vec3 unpackNormalOct8(uint bits) { return octDecode(unpackSnorm4x8(bits & 0xFFFFu).xy); }

// The VPL gather runs at 1/scale resolution per axis (RendererOptions::indirectScale): gather
// pixel q shades the canvas pixel q * scale + (scale - 1) / 2, the middle of its scale x scale
// block (rounded down), so that the samples are spread evenly and the upsampling's bilinear
// weights see them where they are. Clamped to the canvas (the gather buffer rounds up).
ivec2 gatherCanvasPixel(ivec2 q, int scale, ivec2 canvasSize) {
    return min(q * scale + (scale - 1) / 2, canvasSize - 1);
}
// Canvas pixel position c (pixel centres at integers) in gather pixel coordinates (gather pixel
// centres at integers): the inverse of gatherCanvasPixel.
vec2 canvasToGather(vec2 c, int scale) { return (c - float((scale - 1) / 2)) / float(scale); }

#endif
