#pragma once
// Scattering at a surface point of the reference renderer: the glTF 2.0 metallic-roughness model
// (Lambert + GGX microfacet, Fresnel from KHR_materials_ior) mixed with a dielectric
// transmission lobe (KHR_materials_transmission), smooth or rough (Walter et al. 2007), plus
// perfect mirrors. All directions are in the local shading frame (+Z = shading normal) and point
// away from the surface. Values returned by eval() are BSDF values f (1/sr), without the cosine.
//
// Delta ("specular") lobes — perfect mirrors and smooth dielectrics — cannot be evaluated, only
// sampled. The path tracer never connects lights through them; the photon map carries that light
// (docs/reference-renderer.md, "Partition of paths").
#include <glm/glm.hpp>

namespace mirage::raytrace {

// Radiance is scaled by 1/eta^2 when it crosses an interface; importance (photon flux) is not.
enum class TransportMode { Radiance, Importance };

// Material parameters at one surface point (textures already applied). Colours are linear.
struct BsdfParams {
    glm::vec3 baseColor{1.0f};
    float metallic = 0.0f;
    float roughness = 1.0f;     // perceptual roughness; GGX alpha = roughness^2
    float ior = 1.5f;           // of the material relative to the outside (air)
    float transmission = 0.0f;  // KHR_materials_transmission
    bool mirror = false;        // perfect mirror (Material::isMirror)
};

// Perceptual roughness at or below which a dielectric is treated as perfectly smooth (delta).
inline constexpr float kSmoothRoughness = 0.05f;

// Unpolarised Fresnel reflectance of a dielectric interface. cosThetaI is measured against the
// normal on the incident side's convention: positive = arriving from the outside; eta = n_inside
// / n_outside. Returns 1 under total internal reflection.
float fresnelDielectric(float cosThetaI, float eta);

class Bsdf {
public:
    explicit Bsdf(const BsdfParams& p);

    struct Sample {
        glm::vec3 wi{0.0f};
        glm::vec3 weight{0.0f};  // f * |cos(wi)| / pdf, or the delta lobe's weight
        float pdf = 0.0f;        // solid-angle pdf of the non-delta strategy; 0 for delta samples
        bool delta = false;
        bool transmitted = false;
    };

    bool hasNonDelta() const {
        return (opaqueWeight_ > 0 && !p_.mirror) || (transWeight_ > 0 && !smoothDielectric_);
    }
    bool hasDelta() const {
        return (opaqueWeight_ > 0 && p_.mirror) || (transWeight_ > 0 && smoothDielectric_);
    }
    bool isTransmissive() const { return transWeight_ > 0; }

    // Non-delta part of f(wo, wi) and the pdf with which sample() picks wi through it.
    glm::vec3 eval(const glm::vec3& wo, const glm::vec3& wi, TransportMode mode) const;
    float pdf(const glm::vec3& wo, const glm::vec3& wi) const;
    // Samples a direction; returns false when the sample carries no energy.
    bool sample(const glm::vec3& wo, float uLobe, glm::vec2 u, TransportMode mode,
                Sample& out) const;

private:
    glm::vec3 evalOpaque(const glm::vec3& wo, const glm::vec3& wi) const;
    float pdfOpaque(const glm::vec3& wo, const glm::vec3& wi) const;
    bool sampleOpaque(const glm::vec3& wo, float uLobe, glm::vec2 u, Sample& out) const;
    glm::vec3 evalRoughDielectric(const glm::vec3& wo, const glm::vec3& wi,
                                  TransportMode mode) const;
    float pdfRoughDielectric(const glm::vec3& wo, const glm::vec3& wi) const;
    bool sampleDielectric(const glm::vec3& wo, float uLobe, glm::vec2 u, TransportMode mode,
                          Sample& out) const;
    float specularProbability(const glm::vec3& wo) const;

    BsdfParams p_;
    float alpha_ = 1.0f;
    float opaqueWeight_ = 1.0f, transWeight_ = 0.0f;  // mixture weights, sum to 1
    float opaqueMetallic_ = 0.0f;                     // metallic share inside the opaque component
    bool smoothDielectric_ = false;
};

}  // namespace mirage::raytrace
