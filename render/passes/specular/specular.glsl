// Helpers shared by the specular passes (include after common.glsl). Linear radiance, world
// frame (glTF, metres, +Y up).
#ifndef MIRAGE_SPECULAR_GLSL
#define MIRAGE_SPECULAR_GLSL

// Unpolarised Fresnel reflectance of a smooth dielectric interface, exactly as the reference
// renderer's fresnelDielectric: cosI > 0 arrives from the outside, eta = n_inside / n_outside.
// 1 under total internal reflection; 0 for eta = 1 (the interface vanishes).
float fresnelDielectric(float cosI, float eta) {
    cosI = clamp(cosI, -1.0, 1.0);
    if (cosI < 0.0) {
        eta = 1.0 / eta;
        cosI = -cosI;
    }
    float sin2I = max(0.0, 1.0 - cosI * cosI);
    float sin2T = sin2I / (eta * eta);
    if (sin2T >= 1.0) return 1.0;
    float cosT = sqrt(max(0.0, 1.0 - sin2T));
    float rPar = (eta * cosI - cosT) / (eta * cosI + cosT);
    float rPerp = (cosI - eta * cosT) / (cosI + eta * cosT);
    return 0.5 * (rPar * rPar + rPerp * rPerp);
}

vec3 schlickColour(vec3 f0, float cosTheta) {
    float c = clamp(1.0 - abs(cosTheta), 0.0, 1.0);
    float c2 = c * c;
    return f0 + (1.0 - f0) * (c2 * c2 * c);
}

// Environment radiance (linear, intensity applied) in world direction l from the
// equirectangular map: u = 0.5 + (atan2(l.x, -l.z) - rotation) / 2pi, v = acos(l.y) / pi
// (GpuScene::environmentMap, the reference renderer's convention).
vec3 environmentRadiance(sampler2D envMap, vec3 l) {
    if (envOrigin == ORIGIN_NONE) return vec3(0.0);
    l = normalize(l);
    float phi = atan(l.x, -l.z) - envRotation;
    float u = 0.5 + phi / (2.0 * PI);
    float v = acos(clamp(l.y, -1.0, 1.0)) / PI;
    // Explicit LOD 0: the u wrap at +-pi would otherwise pick a tiny mip (there is one level).
    return textureLod(envMap, vec2(u, v), 0.0).rgb;
}

// Canvas pixel (OpenCV convention, (0,0) = centre of the top-left pixel) of world point x;
// returns false behind the camera.
bool projectToCanvas(vec3 x, out vec2 canvasPx) {
    vec4 c = viewProj * vec4(x, 1.0);
    canvasPx = vec2(-1e4);
    if (c.w <= 1e-6) return false;
    canvasPx = (c.xy / c.w * 0.5 + 0.5) * canvas.xy - 0.5;
    return true;
}

#endif
