#include "render/raytrace/Bsdf.h"

#include <algorithm>
#include <cmath>

#include "render/raytrace/Sampling.h"

namespace mirage::raytrace {
namespace {

inline float cos2Theta(const glm::vec3& w) {
    return w.z * w.z;
}
inline float tan2Theta(const glm::vec3& w) {
    float c2 = cos2Theta(w);
    return std::max(0.0f, 1.0f - c2) / c2;
}
inline glm::vec3 reflectAbout(const glm::vec3& wo, const glm::vec3& n) {
    return -wo + 2.0f * glm::dot(wo, n) * n;
}

glm::vec3 schlick(const glm::vec3& f0, float cosTheta) {
    float c = std::clamp(1.0f - std::abs(cosTheta), 0.0f, 1.0f);
    float c5 = c * c * c * c * c;
    return f0 + (glm::vec3(1.0f) - f0) * c5;
}

// Refracts wi (pointing away from the surface) through the interface with normal n; eta =
// n_inside/n_outside relative to n. etap receives the relative IOR actually used.
bool refract(const glm::vec3& wi, glm::vec3 n, float eta, float& etap, glm::vec3& wt) {
    float cosI = glm::dot(n, wi);
    if (cosI < 0) {
        eta = 1.0f / eta;
        cosI = -cosI;
        n = -n;
    }
    float sin2I = std::max(0.0f, 1.0f - cosI * cosI);
    float sin2T = sin2I / (eta * eta);
    if (sin2T >= 1.0f) return false;  // total internal reflection
    float cosT = std::sqrt(1.0f - sin2T);
    wt = -wi / eta + (cosI / eta - cosT) * n;
    etap = eta;
    return true;
}

// GGX (Trowbridge-Reitz) with the height-correlated Smith masking-shadowing term.
struct Ggx {
    float alpha;
    float D(const glm::vec3& wm) const {
        float c2 = cos2Theta(wm);
        if (c2 <= 0) return 0;
        float a2 = alpha * alpha, d = c2 * (a2 - 1.0f) + 1.0f;
        return a2 / (kPi * d * d);
    }
    float lambda(const glm::vec3& w) const {
        if (w.z == 0) return 1e30f;
        return 0.5f * (std::sqrt(1.0f + alpha * alpha * tan2Theta(w)) - 1.0f);
    }
    float G1(const glm::vec3& w) const { return 1.0f / (1.0f + lambda(w)); }
    float G(const glm::vec3& wo, const glm::vec3& wi) const {
        return 1.0f / (1.0f + lambda(wo) + lambda(wi));
    }
    // Density of visible normals seen from w (Heitz 2018), over solid angle of wm.
    float Dvis(const glm::vec3& w, const glm::vec3& wm) const {
        float c = std::abs(w.z);
        return c > 0 ? G1(w) / c * D(wm) * std::abs(glm::dot(w, wm)) : 0.0f;
    }
    // Samples a visible normal (upper hemisphere) seen from w (Heitz 2018).
    glm::vec3 sampleVisible(glm::vec3 w, glm::vec2 u) const {
        glm::vec3 vh = glm::normalize(glm::vec3(alpha * w.x, alpha * w.y, w.z));
        if (vh.z < 0) vh = -vh;
        float lensq = vh.x * vh.x + vh.y * vh.y;
        glm::vec3 t1 =
            lensq > 0 ? glm::vec3(-vh.y, vh.x, 0) / std::sqrt(lensq) : glm::vec3(1, 0, 0);
        glm::vec3 t2 = glm::cross(vh, t1);
        float r = std::sqrt(u.x), phi = 2.0f * kPi * u.y;
        float p1 = r * std::cos(phi), p2 = r * std::sin(phi);
        float s = 0.5f * (1.0f + vh.z);
        p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * p2;
        glm::vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
        return glm::normalize(glm::vec3(alpha * nh.x, alpha * nh.y, std::max(1e-6f, nh.z)));
    }
};

}  // namespace

float fresnelDielectric(float cosThetaI, float eta) {
    cosThetaI = std::clamp(cosThetaI, -1.0f, 1.0f);
    if (cosThetaI < 0) {
        eta = 1.0f / eta;
        cosThetaI = -cosThetaI;
    }
    float sin2I = 1.0f - cosThetaI * cosThetaI;
    float sin2T = sin2I / (eta * eta);
    if (sin2T >= 1.0f) return 1.0f;
    float cosT = std::sqrt(std::max(0.0f, 1.0f - sin2T));
    float rPar = (eta * cosThetaI - cosT) / (eta * cosThetaI + cosT);
    float rPerp = (cosThetaI - eta * cosT) / (cosThetaI + eta * cosT);
    return 0.5f * (rPar * rPar + rPerp * rPerp);
}

Bsdf::Bsdf(const BsdfParams& p) : p_(p) {
    p_.metallic = std::clamp(p_.metallic, 0.0f, 1.0f);
    p_.transmission = std::clamp(p_.transmission, 0.0f, 1.0f);
    p_.roughness = std::clamp(p_.roughness, 0.0f, 1.0f);
    p_.baseColor = glm::clamp(p_.baseColor, 0.0f, 1.0f);
    if (!(p_.ior > 0.0f) || !std::isfinite(p_.ior)) p_.ior = 1.5f;
    // Below alpha ~1e-3 GGX is numerically a delta lobe but evaluated with float round-off.
    alpha_ = std::max(p_.roughness * p_.roughness, 2e-3f);
    // glTF: f = mix(mix(dielectric_brdf, dielectric_btdf, transmission), metal_brdf, metallic).
    transWeight_ = p_.mirror ? 0.0f : p_.transmission * (1.0f - p_.metallic);
    opaqueWeight_ = 1.0f - transWeight_;
    opaqueMetallic_ = opaqueWeight_ > 0 ? std::min(1.0f, p_.metallic / opaqueWeight_) : 0.0f;
    smoothDielectric_ = p_.roughness <= kSmoothRoughness;
}

// ---- opaque component: glTF metallic-roughness BRDF, or a perfect mirror --------------------

float Bsdf::specularProbability(const glm::vec3& wo) const {
    float m = opaqueMetallic_;
    if (m >= 1.0f) return 1.0f;
    float fd = fresnelDielectric(wo.z, p_.ior);
    if (p_.ior == 1.0f && m == 0.0f) return 0.0f;  // no specular layer at all
    return std::clamp((1.0f - m) * fd + m, 0.05f, 0.95f);
}

glm::vec3 Bsdf::evalOpaque(const glm::vec3& wo, const glm::vec3& wi) const {
    if (p_.mirror || wo.z <= 0 || wi.z <= 0) return glm::vec3(0.0f);
    glm::vec3 wm = wo + wi;
    if (glm::dot(wm, wm) == 0) return glm::vec3(0.0f);
    wm = glm::normalize(wm);
    float cosOH = glm::dot(wo, wm);
    float m = opaqueMetallic_;
    float fd = fresnelDielectric(cosOH, p_.ior);
    glm::vec3 fresnel = (1.0f - m) * glm::vec3(fd) + m * schlick(p_.baseColor, cosOH);
    Ggx ggx{alpha_};
    glm::vec3 spec = fresnel * (ggx.D(wm) * ggx.G(wo, wi) / (4.0f * wo.z * wi.z));
    glm::vec3 diffuse = (1.0f - m) * (1.0f - fd) * p_.baseColor * kInvPi;
    return spec + diffuse;
}

float Bsdf::pdfOpaque(const glm::vec3& wo, const glm::vec3& wi) const {
    if (p_.mirror || wo.z <= 0 || wi.z <= 0) return 0.0f;
    float ps = specularProbability(wo);
    glm::vec3 wm = glm::normalize(wo + wi);
    Ggx ggx{alpha_};
    float pSpec = ggx.Dvis(wo, wm) / (4.0f * std::abs(glm::dot(wo, wm)));
    return ps * pSpec + (1.0f - ps) * wi.z * kInvPi;
}

bool Bsdf::sampleOpaque(const glm::vec3& wo, float uLobe, glm::vec2 u, Sample& out) const {
    if (wo.z <= 0) return false;
    if (p_.mirror) {
        out.wi = {-wo.x, -wo.y, wo.z};
        out.weight = schlick(p_.baseColor, wo.z);
        out.pdf = 0.0f;
        out.delta = true;
        out.transmitted = false;
        return true;
    }
    float ps = specularProbability(wo);
    glm::vec3 wi;
    if (uLobe < ps) {
        glm::vec3 wm = Ggx{alpha_}.sampleVisible(wo, u);
        wi = reflectAbout(wo, wm);
    } else {
        wi = sampleCosineHemisphere(u);
    }
    if (wi.z <= 0) return false;
    out.wi = wi;
    out.pdf = pdfOpaque(wo, wi);
    if (!(out.pdf > 0)) return false;
    out.weight = evalOpaque(wo, wi) * wi.z / out.pdf;
    out.delta = false;
    out.transmitted = false;
    return true;
}

// ---- transmission component: smooth or rough dielectric -----------------------------------

glm::vec3 Bsdf::evalRoughDielectric(const glm::vec3& wo, const glm::vec3& wi,
                                    TransportMode mode) const {
    if (smoothDielectric_) return glm::vec3(0.0f);
    float cosO = wo.z, cosI = wi.z;
    if (cosO == 0 || cosI == 0) return glm::vec3(0.0f);
    bool reflect = cosO * cosI > 0;
    float etap = reflect ? 1.0f : (cosO > 0 ? p_.ior : 1.0f / p_.ior);
    glm::vec3 wm = wi * etap + wo;
    if (glm::dot(wm, wm) == 0) return glm::vec3(0.0f);
    wm = glm::normalize(wm);
    if (wm.z < 0) wm = -wm;
    if (glm::dot(wm, wi) * cosI < 0 || glm::dot(wm, wo) * cosO < 0) return glm::vec3(0.0f);
    float F = fresnelDielectric(glm::dot(wo, wm), p_.ior);
    Ggx ggx{alpha_};
    if (reflect) return glm::vec3(ggx.D(wm) * ggx.G(wo, wi) * F / std::abs(4.0f * cosI * cosO));
    float denom = glm::dot(wi, wm) + glm::dot(wo, wm) / etap;
    denom *= denom;
    float ft = ggx.D(wm) * (1.0f - F) * ggx.G(wo, wi) *
               std::abs(glm::dot(wi, wm) * glm::dot(wo, wm) / (cosI * cosO * denom));
    if (mode == TransportMode::Radiance) ft /= etap * etap;
    return p_.baseColor * ft;
}

float Bsdf::pdfRoughDielectric(const glm::vec3& wo, const glm::vec3& wi) const {
    if (smoothDielectric_) return 0.0f;
    float cosO = wo.z, cosI = wi.z;
    if (cosO == 0 || cosI == 0) return 0.0f;
    bool reflect = cosO * cosI > 0;
    float etap = reflect ? 1.0f : (cosO > 0 ? p_.ior : 1.0f / p_.ior);
    glm::vec3 wm = wi * etap + wo;
    if (glm::dot(wm, wm) == 0) return 0.0f;
    wm = glm::normalize(wm);
    if (wm.z < 0) wm = -wm;
    if (glm::dot(wm, wi) * cosI < 0 || glm::dot(wm, wo) * cosO < 0) return 0.0f;
    float R = fresnelDielectric(glm::dot(wo, wm), p_.ior), T = 1.0f - R;
    Ggx ggx{alpha_};
    if (reflect) return ggx.Dvis(wo, wm) / (4.0f * std::abs(glm::dot(wo, wm))) * R;
    float denom = glm::dot(wi, wm) + glm::dot(wo, wm) / etap;
    float dwmDwi = std::abs(glm::dot(wi, wm)) / (denom * denom);
    return ggx.Dvis(wo, wm) * dwmDwi * T;
}

bool Bsdf::sampleDielectric(const glm::vec3& wo, float uLobe, glm::vec2 u, TransportMode mode,
                            Sample& out) const {
    if (wo.z == 0) return false;
    if (smoothDielectric_) {
        float R = fresnelDielectric(wo.z, p_.ior);
        out.pdf = 0.0f;
        out.delta = true;
        if (uLobe < R) {
            out.wi = {-wo.x, -wo.y, wo.z};
            out.weight = glm::vec3(1.0f);  // F / P(reflect) with P = F
            out.transmitted = false;
            return true;
        }
        float etap;
        glm::vec3 wt;
        if (!refract(wo, glm::vec3(0, 0, 1), p_.ior, etap, wt)) return false;
        out.wi = wt;
        out.weight = p_.baseColor * (mode == TransportMode::Radiance ? 1.0f / (etap * etap) : 1.0f);
        out.transmitted = true;
        return true;
    }
    Ggx ggx{alpha_};
    glm::vec3 wm = ggx.sampleVisible(wo, u);
    float R = fresnelDielectric(glm::dot(wo, wm), p_.ior);
    glm::vec3 wi;
    if (uLobe < R) {
        wi = reflectAbout(wo, wm);
        if (wi.z * wo.z <= 0) return false;
        out.transmitted = false;
    } else {
        float etap;
        if (!refract(wo, wm, p_.ior, etap, wi)) return false;
        if (wi.z * wo.z >= 0 || wi.z == 0) return false;
        out.transmitted = true;
    }
    out.wi = wi;
    out.pdf = pdfRoughDielectric(wo, wi);
    if (!(out.pdf > 0)) return false;
    out.weight = evalRoughDielectric(wo, wi, mode) * std::abs(wi.z) / out.pdf;
    out.delta = false;
    return true;
}

// ---- the mixture ------------------------------------------------------------------------------

glm::vec3 Bsdf::eval(const glm::vec3& wo, const glm::vec3& wi, TransportMode mode) const {
    glm::vec3 f(0.0f);
    if (opaqueWeight_ > 0) f += opaqueWeight_ * evalOpaque(wo, wi);
    if (transWeight_ > 0) f += transWeight_ * evalRoughDielectric(wo, wi, mode);
    return f;
}

float Bsdf::pdf(const glm::vec3& wo, const glm::vec3& wi) const {
    float p = 0.0f;
    if (opaqueWeight_ > 0) p += opaqueWeight_ * pdfOpaque(wo, wi);
    if (transWeight_ > 0) p += transWeight_ * pdfRoughDielectric(wo, wi);
    return p;
}

bool Bsdf::sample(const glm::vec3& wo, float uLobe, glm::vec2 u, TransportMode mode,
                  Sample& out) const {
    bool ok;
    if (uLobe < transWeight_) {
        ok = sampleDielectric(wo, uLobe / transWeight_, u, mode, out);
        if (!ok || out.delta) return ok && isFiniteVec(out.weight);
    } else {
        float ul = transWeight_ > 0 ? (uLobe - transWeight_) / opaqueWeight_ : uLobe;
        ok = sampleOpaque(wo, std::min(ul, 0x1.fffffep-1f), u, out);
        if (!ok || out.delta) return ok && isFiniteVec(out.weight);
    }
    // Non-delta sample of one component: weight and pdf must be those of the whole mixture so
    // that MIS sees the true density of this strategy.
    out.pdf = pdf(wo, out.wi);
    if (!(out.pdf > 0)) return false;
    out.weight = eval(wo, out.wi, mode) * std::abs(out.wi.z) / out.pdf;
    return isFiniteVec(out.weight);
}

}  // namespace mirage::raytrace
