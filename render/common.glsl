// Shared GPU data layout of the real-time renderer. Mirrored by render/GpuTypes.h (std140, no
// bool: flags are ints). Frames: world = glTF (metres, +Y up); camera = OpenCV (+X right, +Y
// down, +Z forward). Every radiance value here is LINEAR RGB (W / (m^2 sr), with the scene's
// exposure convention that 1.0 is the camera's white).
#ifndef MIRAGE_COMMON_GLSL
#define MIRAGE_COMMON_GLSL

#define MAX_LIGHTS 8
#define LIGHT_POINT 0
#define LIGHT_SPOT 1
#define LIGHT_DIRECTIONAL 2
#define ORIGIN_NONE 0
#define ORIGIN_REAL 1
#define ORIGIN_VIRTUAL 2
#define PI 3.14159265358979

struct GpuLight {
    mat4 viewProj[6];     // world -> light clip space, one per shadow layer (spot/dir use [0])
    vec4 positionRange;   // xyz world position (metres); w = range (0 = infinite)
    vec4 directionType;   // xyz unit direction the light shines along; w = LIGHT_* type
    vec4 radiantIntensity;  // rgb = colour * intensity: W/sr (point, spot) or W/m^2 (dir.)
    vec4 cone;            // x = cos(outer), y = cos(inner), z = angle scale, w = angle offset
    ivec4 shadow;         // x = first layer in the shadow atlases, y = layer count (0 = none),
                          // z = 1 if the real-only map differs from the all-occluder map
                          // (a virtual caster is in the cone), w = 1 if the light is real
};

layout(std140, binding = 0) uniform FrameBlock {
    mat4 viewMatrix;       // world -> OpenCV camera
    mat4 projMatrix;       // OpenCV camera -> GL clip (render canvas, undistorted)
    mat4 viewProj;
    mat4 prevViewProj;     // last frame's, for temporal reprojection
    vec4 cameraPos;        // xyz world (metres)
    vec4 prevCameraPos;    // xyz world (metres)
    vec4 canvas;           // render canvas width, height, 1/width, 1/height (pixels)
    ivec4 counts;          // x = lights, y = VPLs, z = interleave tile size K, w = frame index
    ivec4 flags;           // x = env light on, y = history valid, z = ISM tile size, w = ISM tiles/row
    vec4 params;           // x = VPL distance clamp (m), y = shadow bias (m), z = temporal blend,
                           // w = ISM points per VPL
    vec4 envSH[9];         // environment irradiance SH (rgb), already scaled by intensity
    vec4 exposure;         // x = exposure multiplier for rendered radiance, y = alpha max,
                           // z = L_r threshold below which alpha fades to 1, w = environment
                           // map rotation about +Y (radians, rotation_y_deg of the scene)
};

layout(std140, binding = 1) uniform LightBlock { GpuLight lights[MAX_LIGHTS]; };

// One virtual point light (std430 SSBO, binding 2).
struct GpuVpl {
    vec4 positionReal;  // xyz world position; w = 1 if light, surface q are real, else 0
    vec4 normal;        // xyz unit normal at q (facing the light); w = 1 valid, 0 unused slot
    vec4 flux;          // rgb = reflected power (W) the VPL emits (cosine lobe); w unused
    vec4 tangent;       // xyz unit tangent; with cross(normal, tangent): the ISM paraboloid frame
};

// Paraboloid coordinates (unit disc) of unit direction w around a VPL's normal (z axis).
vec2 paraboloidUv(GpuVpl V, vec3 w) {
    vec3 b = cross(V.normal.xyz, V.tangent.xyz);
    return vec2(dot(w, V.tangent.xyz), dot(w, b)) / (1.0 + dot(w, V.normal.xyz));
}

// Materials (std430 SSBO, binding 3).
struct GpuMaterial {
    vec4 baseColor;   // linear RGBA
    vec4 emissive;    // rgb linear emitted radiance; w = roughness
    vec4 params;      // x = metallic
    vec4 transmission;  // x = transmission (0..1), y = ior, z = attenuation distance (m, 0 =
                        // none), w = thickness (mesh units, informational)
    vec4 attenuation;   // rgb = linear attenuation colour, a = 1 for a perfect mirror
};

// Specular draw table (std430 SSBO, binding 5), indexed by specular slot (GpuScene::
// specularDraws() order). The G-buffer stores slot + 1 in gEmissive.a (0 = not specular).
struct GpuSpecularDraw {
    ivec4 info;   // x = material index, y = ORIGIN_REAL / ORIGIN_VIRTUAL, z = draw index
    vec4 bounds;  // world bounding sphere: xyz centre, w radius (metres)
};

// glTF KHR_lights_punctual spot cone and range window (the spec's recommended falloff).
// Lights are passed by index, never copied: a GpuLight is 464 bytes and llvmpipe copies it per
// pixel if a shader takes it by value.
float spotAttenuation(int li, vec3 lightToPoint) {
    if (int(lights[li].directionType.w) != LIGHT_SPOT) return 1.0;
    vec4 cone = lights[li].cone;
    float cd = dot(lights[li].directionType.xyz, lightToPoint);
    float a = clamp(cd * cone.z + cone.w, 0.0, 1.0);
    return a * a;
}
float rangeWindow(int li, float dist) {
    float range = lights[li].positionRange.w;
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

#endif
