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

// Half-resolution specular lighting (specular_light.frag MIRAGE_SPECULAR_HALF,
// specular_resolve.frag): hit radiance is stored divided by (albedo + this floor) and multiplied
// back by the full-resolution hit's, so texture detail at the hits stays sharp; the floor keeps
// black hits finite.
const float kSpecularDemodulationFloor = 0.05;

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

// Canvas-style pixel of world point x in a view (world -> clip `vp`, `size` texels): (0,0) = the
// centre of the first texel; false behind the eye. The camera's view is projectToCanvas below.
bool clipToView(vec4 c, vec2 size, out vec2 px) {
    px = vec2(-1e4);
    if (c.w <= 1e-6) return false;
    px = (c.xy / c.w * 0.5 + 0.5) * size - 0.5;
    return true;
}
bool projectToView(mat4 vp, vec2 size, vec3 x, out vec2 px) {
    return clipToView(vp * vec4(x, 1.0), size, px);
}

// The share of the light a specular material refracts (transWeight below): transmission x
// (1 - metallic), 0 for a perfect mirror.
float transmissionShare(GpuMaterial m) {
    if (m.mirror != 0) return 0.0;
    return clamp(m.transmission, 0.0, 1.0) * (1.0 - clamp(m.metallic, 0.0, 1.0));
}

// Reflection weight of a smooth surface with material m at cos(theta) = cosV (Fresnel of `ior`
// for dielectrics, mixed by transmission / metallic as the reference does; Schlick(baseColour)
// for a perfect mirror). transWeight = transmission (1 - metallic), 0 for mirrors.
vec3 reflectionWeight(GpuMaterial m, float cosV, float transWeight) {
    vec3 base = clamp(m.baseColor.rgb, 0.0, 1.0);
    if (m.mirror != 0) return schlickColour(base, cosV);  // perfect mirror
    float F = fresnelDielectric(cosV, max(m.ior, 1e-3));
    float opaque = 1.0 - transWeight;
    float metal = opaque > 0.0 ? min(1.0, clamp(m.metallic, 0.0, 1.0) / opaque) : 0.0;
    vec3 opaqueF = (1.0 - metal) * vec3(F) + metal * schlickColour(base, cosV);
    return transWeight * vec3(F) + opaque * opaqueF;
}

// Exit of a ray inside the object with bounding sphere (c, r): the far intersection.
vec3 sphereExit(vec3 o, vec3 d, vec3 centre, float radius) {
    vec3 oc = o - centre;
    float b = dot(oc, d);
    float cc = dot(oc, oc) - radius * radius;
    float disc = max(b * b - cc, 0.0);
    return o + max(-b + sqrt(disc), 0.0) * d;
}

// Two-interface refraction (Wyman 2005) of the ray arriving along unit d at front-face point p
// (unit normal n facing the ray's origin) of specular slot `slot`, seen from a view: `vp` world ->
// clip, `eye` its centre (world), `size` its buffer size, and that view's nearest back faces of
// the specular objects (backPosition: xyz world, w = slot + 1; backNormal: outward). The camera
// path (specular_gbuffer.frag) and the photon path from a spot light (passes/caustic) both call
// it with their own view. T1 = Snell at the front face; the exit P2 is where T1, marched in
// `marchSteps` steps over the bounding diameter, passes the back face the view stores at its
// pixel (same object), refined by 6 bisection steps; off the object's back-face footprint the far
// bounding-sphere intersection stands in. T2 = Snell at the back face (outward normal N2); total
// internal reflection there: ONE internal reflection T2 = reflect(T1, -N2) with F2 = 0
// (docs/specular.md). Returns false when nothing is refracted (TIR at the front face, ior < 1).
// Outputs the exit point P2 and unit direction T2, the two Fresnel reflectances and the distance
// travelled inside (m).
// N2 (this overload): the back face's outward unit normal at P2.
bool refractTwoInterfaces(vec3 p, vec3 n, vec3 d, int slot, GpuSpecularDraw sd, float eta,
                          mat4 vp, vec3 eye, vec2 size, sampler2D backPosition,
                          sampler2D backNormal, int marchSteps, out vec3 P2, out vec3 T2,
                          out float F1, out float F2, out float inside, out vec3 N2) {
    N2 = -d;
    P2 = p;
    T2 = d;
    F2 = 0.0;
    inside = 0.0;
    float cosV = clamp(dot(n, -d), 1e-4, 1.0);  // grazing: clamped, never 0
    F1 = fresnelDielectric(cosV, eta);
    vec3 T1 = refract(d, n, 1.0 / eta);
    if (F1 >= 1.0 || dot(T1, T1) < 0.5) return false;  // TIR at the front face (ior < 1)
    T1 = normalize(T1);
    // March T1 through the back-face buffer: the exit is where the ray's distance from the eye
    // passes the stored back face's (same object).
    float maxLen = 2.0 * sd.radius + 1e-3;
    int steps = clamp(marchSteps, 2, 128);
    // Clip coordinates are linear along the ray: vp (p + t T1) = clipP + t clipT1, one
    // multiply-add per sample instead of a matrix product.
    vec4 clipP = vp * vec4(p, 1.0), clipT1 = vp * vec4(T1, 0.0);
    float prevT = 0.0, hitT = -1.0;
    for (int i = 1; i <= steps; ++i) {
        float t = maxLen * float(i) / float(steps);
        vec3 q = p + T1 * t;
        vec2 cp;
        if (!clipToView(clipP + t * clipT1, size, cp)) break;
        ivec2 qi = ivec2(floor(cp + 0.5));
        if (any(lessThan(qi, ivec2(0))) || any(greaterThanEqual(qi, ivec2(size)))) break;
        vec4 B = texelFetch(backPosition, qi, 0);
        if (int(B.w + 0.5) - 1 != slot) break;  // left the object's back-face footprint
        if (length(q - eye) >= length(B.xyz - eye)) {
            hitT = t;
            break;
        }
        prevT = t;
    }
    if (hitT > 0.0) {
        float lo = prevT, hi = hitT;
        for (int k = 0; k < 6; ++k) {  // bisection on the same crossing test
            float mid = 0.5 * (lo + hi);
            vec3 q = p + T1 * mid;
            vec2 cp;
            clipToView(clipP + mid * clipT1, size, cp);
            ivec2 qi = clamp(ivec2(floor(cp + 0.5)), ivec2(0), ivec2(size) - 1);
            vec4 B = texelFetch(backPosition, qi, 0);
            bool past = int(B.w + 0.5) - 1 != slot || length(q - eye) >= length(B.xyz - eye);
            if (past) hi = mid; else lo = mid;
        }
        P2 = p + T1 * hi;
        vec2 cp;
        projectToView(vp, size, P2, cp);
        ivec2 qi = clamp(ivec2(floor(cp + 0.5)), ivec2(0), ivec2(size) - 1);
        N2 = texelFetch(backNormal, qi, 0).xyz;
        if (int(texelFetch(backPosition, qi, 0).w + 0.5) - 1 != slot || dot(N2, N2) < 0.25)
            N2 = normalize(P2 - sd.centre);
    } else {
        P2 = sphereExit(p, T1, sd.centre, sd.radius);
        N2 = normalize(P2 - sd.centre);
    }
    N2 = normalize(N2);
    if (!allFinite(N2)) N2 = T1;
    if (dot(N2, T1) < 1e-3) N2 = normalize(N2 + T1 * (1e-3 - dot(N2, T1)));  // leaves outward
    inside = length(P2 - p);
    float cos2 = clamp(dot(T1, N2), 1e-4, 1.0);  // inside, towards the outward normal
    F2 = fresnelDielectric(-cos2, eta);           // from the inside: relative ior 1 / eta
    T2 = refract(T1, -N2, eta);
    if (F2 >= 1.0 || dot(T2, T2) < 0.5) {
        T2 = reflect(T1, -N2);  // TIR: one internal reflection, then out (documented)
        F2 = 0.0;               // all of it continues along T2
    }
    T2 = normalize(T2);
    return true;
}

bool refractTwoInterfaces(vec3 p, vec3 n, vec3 d, int slot, GpuSpecularDraw sd, float eta,
                          mat4 vp, vec3 eye, vec2 size, sampler2D backPosition,
                          sampler2D backNormal, int marchSteps, out vec3 P2, out vec3 T2,
                          out float F1, out float F2, out float inside) {
    vec3 N2;
    return refractTwoInterfaces(p, n, d, slot, sd, eta, vp, eye, size, backPosition, backNormal,
                                marchSteps, P2, T2, F1, F2, inside, N2);
}

// Weight of the light refracted through both interfaces: transmission (1 - F1)(1 - F2)
// baseColour^2 (the reference tints each crossing by baseColour) x Beer-Lambert
// attenuationColour^(inside / attenuationDistance) (KHR_materials_volume; inside in metres).
vec3 refractionWeight(GpuMaterial m, float transWeight, float F1, float F2, float inside) {
    vec3 base = clamp(m.baseColor.rgb, 0.0, 1.0);
    vec3 absorb = vec3(1.0);
    if (m.attenuationDistance > 0.0)
        absorb = pow(max(m.attenuationColor, vec3(1e-6)), vec3(inside / m.attenuationDistance));
    return transWeight * (1.0 - F1) * (1.0 - F2) * base * base * absorb;
}

// Canvas pixel (OpenCV convention, (0,0) = centre of the top-left pixel) of world point x;
// returns false behind the camera.
bool projectToCanvas(vec3 x, out vec2 canvasPx) {
    return projectToView(viewProj, canvas.xy, x, canvasPx);
}

// CI(x) (Knecht 2013 Eqs. 8-10): the camera image where world point x appears, if the video shows
// x there. Valid when x is in front of the camera, inside the canvas and the camera image, and
// the nearest REAL surface at that pixel (realSurfaces: xyz world, w = origin) has the same camera
// distance within depthEpsilon * distance + 5 mm. canvasToCamera: canvas -> camera-image pixel
// (lens distortion; not read under MIRAGE_IDENTITY_REMAP, where the canvas is the camera image);
// cameraImage: sRGB8 texture, so `colour` is linear camera units.
// backProjectPixel: the same test, giving the camera-image pixel instead of its colour.
bool backProjectPixel(vec3 x, sampler2D realSurfaces, sampler2D canvasToCamera,
                      sampler2D cameraImage, float depthEpsilon, out ivec2 pixel) {
    pixel = ivec2(0);
    vec2 cp;
    if (!projectToCanvas(x, cp)) return false;
    ivec2 ci = ivec2(floor(cp + 0.5));
    if (any(lessThan(ci, ivec2(0))) || any(greaterThanEqual(ci, ivec2(canvas.xy)))) return false;
    vec4 S = texelFetch(realSurfaces, ci, 0);
    if (int(S.w + 0.5) != ORIGIN_REAL) return false;
    float dx = length(x - cameraPos.xyz), ds = length(S.xyz - cameraPos.xyz);
    if (abs(dx - ds) > depthEpsilon * dx + 0.005) return false;
#ifdef MIRAGE_IDENTITY_REMAP  // the composite's variant without lens distortion
    vec2 camPx = cp;
#else
    vec2 camPx = texture(canvasToCamera, (cp + 0.5) * canvas.zw).xy;
#endif
    ivec2 size = textureSize(cameraImage, 0);
    if (camPx.x < -0.5 || camPx.y < -0.5 || camPx.x > float(size.x) - 0.5 ||
        camPx.y > float(size.y) - 0.5)
        return false;  // outside the video's frustum
    pixel = clamp(ivec2(floor(camPx + 0.5)), ivec2(0), size - 1);
    return true;
}

bool backProject(vec3 x, sampler2D realSurfaces, sampler2D canvasToCamera, sampler2D cameraImage,
                 float depthEpsilon, out vec3 colour) {
    ivec2 pixel;
    bool ok = backProjectPixel(x, realSurfaces, canvasToCamera, cameraImage, depthEpsilon, pixel);
    colour = ok ? texelFetch(cameraImage, pixel, 0).rgb : vec3(0.0);
    return ok;
}

// Where a ray inside the object, from P2 along unit T1r (the light the back face reflects inside),
// leaves it: P3 and the outward unit normal N3 there. T1r is marched through the object (the
// primary G-buffer's front faces and the back-face buffer of the same draw slot, as the sharp
// path's march: it leaves where it passes in front of a front face or behind a back face,
// bisected); off both buffers' footprint the bounding sphere's exit stands in. False when T1r does
// not leave through the surface found (it grazes it or the normal is not finite).
bool internalPathExit(vec3 P2, vec3 T1r, int slot, GpuSpecularDraw sd, sampler2D frontPosition,
                      sampler2D frontNormal, sampler2D frontSlot, sampler2D backPosition,
                      sampler2D backNormal, out vec3 P3, out vec3 N3) {
    vec2 cp;
    // March T1r inside: out where it is in front of this object's front face or behind its back
    // face at the pixel it projects to; off both, it left the object's image.
    float maxLen = 2.0 * sd.radius + 1e-3;
    const int kSteps = 12;
    float prevT = 0.0, hitT = -1.0;
    int face = 0;  // 1: front face, 2: back face
    for (int i = 1; i <= kSteps && hitT < 0.0; ++i) {
        float t = maxLen * float(i) / float(kSteps);
        vec3 q = P2 + T1r * t;
        if (!projectToCanvas(q, cp)) break;
        ivec2 qi = ivec2(floor(cp + 0.5));
        if (any(lessThan(qi, ivec2(0))) || any(greaterThanEqual(qi, ivec2(canvas.xy)))) break;
        float dq = length(q - cameraPos.xyz);
        bool front = int(texelFetch(frontSlot, qi, 0).a + 0.5) - 1 == slot;
        bool back = int(texelFetch(backPosition, qi, 0).w + 0.5) - 1 == slot;
        if (!front && !back) break;
        if (front && dq < length(texelFetch(frontPosition, qi, 0).xyz - cameraPos.xyz)) face = 1;
        else if (back && dq > length(texelFetch(backPosition, qi, 0).xyz - cameraPos.xyz)) face = 2;
        if (face != 0) hitT = t; else prevT = t;
    }
    if (hitT > 0.0) {
        float lo = prevT, hi = hitT;
        for (int k = 0; k < 5; ++k) {
            float mid = 0.5 * (lo + hi);
            vec3 q = P2 + T1r * mid;
            projectToCanvas(q, cp);
            ivec2 qi = clamp(ivec2(floor(cp + 0.5)), ivec2(0), ivec2(canvas.xy) - 1);
            float dq = length(q - cameraPos.xyz);
            vec4 S = face == 1 ? texelFetch(frontPosition, qi, 0) : texelFetch(backPosition, qi, 0);
            bool same = face == 1 ? int(texelFetch(frontSlot, qi, 0).a + 0.5) - 1 == slot
                                  : int(S.w + 0.5) - 1 == slot;
            float ds = length(S.xyz - cameraPos.xyz);
            bool out_ = !same || (face == 1 ? dq < ds : dq > ds);
            if (out_) hi = mid; else lo = mid;
        }
        P3 = P2 + T1r * hi;
        projectToCanvas(P3, cp);
        ivec2 qi = clamp(ivec2(floor(cp + 0.5)), ivec2(0), ivec2(canvas.xy) - 1);
        N3 = (face == 1 ? texelFetch(frontNormal, qi, 0) : texelFetch(backNormal, qi, 0)).xyz;
        if (dot(N3, N3) < 0.25) N3 = P3 - sd.centre;
    } else {
        P3 = sphereExit(P2, T1r, sd.centre, sd.radius);
        N3 = P3 - sd.centre;
    }
    N3 = normalize(N3);
    return allFinite(N3) && dot(N3, T1r) >= 1e-3;
}

// The refracted path's second exit. The sharp path (refractTwoInterfaces) leaves the back face at
// P2 with the share 1 - F2 of the light; the share F2 is reflected inside, along T1r = reflect(T1,
// N2), meets the object's surface again at P3 (outward normal N3) and leaves along T3 = Snell there
// with 1 - F3. On a glass sphere seen at a grazing angle (its rim) F2 is large and T3 points away
// from everything the sharp path sees: without it the rim is too dark. P3 is where internalPathExit
// finds T1r leaving. Light reflected inside a second time is not followed (nor where the sharp path
// itself took the internal reflection, F2 = 1). weight: that of the light arriving along -T3, given
// the sharp path's refraction weight w2 = ... (1 - F1)(1 - F2) ... absorb(d_in): w2 F2 / (1 - F2)
// (1 - F3) x Beer-Lambert over |P3 - P2|. False when there is none.
bool refractedSecondExit(vec3 a, vec3 n, vec3 d, float din, vec3 w2, GpuMaterial m,
                         GpuSpecularDraw sd, int slot, sampler2D frontPosition,
                         sampler2D frontNormal, sampler2D frontSlot, sampler2D backPosition,
                         sampler2D backNormal, out vec3 P3, out vec3 T3, out vec3 weight) {
    P3 = a;
    T3 = d;
    weight = vec3(0.0);
    float eta = max(m.ior, 1e-3);
    if (all(lessThanEqual(w2, vec3(0.0))) || abs(eta - 1.0) < 1e-4) return false;
    vec3 T1 = refract(d, n, 1.0 / eta);
    if (dot(T1, T1) < 0.5) return false;
    T1 = normalize(T1);
    vec3 P2 = a + T1 * max(din, 0.0);
    vec2 cp;
    vec3 N2 = normalize(P2 - sd.centre);
    if (projectToCanvas(P2, cp)) {
        ivec2 qi = clamp(ivec2(floor(cp + 0.5)), ivec2(0), ivec2(canvas.xy) - 1);
        vec3 Nb = texelFetch(backNormal, qi, 0).xyz;
        if (int(texelFetch(backPosition, qi, 0).w + 0.5) - 1 == slot && dot(Nb, Nb) > 0.25)
            N2 = normalize(Nb);
    }
    if (!allFinite(N2) || dot(N2, T1) < 1e-3) return false;
    float F2 = fresnelDielectric(-dot(T1, N2), eta);
    if (!(F2 > 1e-4) || F2 >= 1.0) return false;
    vec3 T1r = reflect(T1, N2);
    vec3 N3;
    if (!internalPathExit(P2, T1r, slot, sd, frontPosition, frontNormal, frontSlot, backPosition,
                          backNormal, P3, N3))
        return false;
    float F3 = fresnelDielectric(-dot(T1r, N3), eta);
    T3 = refract(T1r, -N3, eta);
    if (F3 >= 1.0 || dot(T3, T3) < 0.5) return false;  // reflected inside again: not followed
    T3 = normalize(T3);
    vec3 absorb = vec3(1.0);
    if (m.attenuationDistance > 0.0)
        absorb = pow(max(m.attenuationColor, vec3(1e-6)),
                     vec3(length(P3 - P2) / m.attenuationDistance));
    weight = w2 * (F2 / (1.0 - F2)) * (1.0 - F3) * absorb;
    return allFinite(weight) && allFinite(T3);
}

#endif
