#include "render/raytrace/ReferenceRenderer.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <thread>

#include "core/Error.h"
#include "core/ParallelFor.h"
#include "render/raytrace/PhotonMap.h"
#include "render/raytrace/Sampling.h"

namespace mirage::raytrace {
namespace {

constexpr uint64_t kPhotonDomain = 0x9E3779B97F4A7C15ull;  // separates photon and pixel streams
constexpr int kTile = 16;

// Offsets a ray origin off the surface to the side `dir` leaves towards.
glm::vec3 spawnOrigin(const SurfaceHit& hit, const glm::vec3& dir) {
    float eps = 1e-4f * std::max(1.0f, maxComponent(glm::abs(hit.p)));
    return hit.p + (glm::dot(dir, hit.ng) >= 0 ? eps : -eps) * hit.ng;
}

glm::vec3 beerLambert(const glm::vec3& sigmaA, float distance) {
    return glm::exp(-sigmaA * distance);
}

// ---- photon emission towards the delta-specular objects ----------------------------------------

struct EmissionTarget {
    int light = 0;
    glm::vec3 axis{0.0f};  // point/spot: unit direction light -> target centre
    float cosMax = -1.0f;  // point/spot cone; -1 = whole sphere
    float solidAngle = 4.0f * kPi;
    glm::vec3 centre{0.0f};  // directional: disk centre and radius
    float radius = 0.0f;
    float probability = 0.0f;
};

class PhotonEmitter {
public:
    explicit PhotonEmitter(const RayTracingScene& scene) : scene_(scene) {
        auto targets = scene.deltaSpecularBounds();
        const auto& lights = scene.lights();
        double total = 0.0;
        for (size_t li = 0; li < lights.size(); ++li) {
            const PunctualLight& l = lights[li];
            float lum = luminance(l.intensity);
            if (!(lum > 0)) continue;
            for (const auto& t : targets) {
                EmissionTarget e;
                e.light = int(li);
                double weight;
                if (l.type == Light::Type::Directional) {
                    e.centre = t.centre;
                    e.radius = std::max(t.radius, 1e-6f);
                    weight = double(lum) * kPi * e.radius * e.radius;
                } else {
                    glm::vec3 v = t.centre - l.position;
                    float d = glm::length(v);
                    if (d <= t.radius * 1.001f) {
                        e.cosMax = -1.0f;
                        e.solidAngle = 4.0f * kPi;
                        e.axis = glm::vec3(0, 0, 1);
                    } else {
                        float sinMax = t.radius / d;
                        e.cosMax = std::sqrt(std::max(0.0f, 1.0f - sinMax * sinMax));
                        e.solidAngle = 2.0f * kPi * (1.0f - e.cosMax);
                        e.axis = v / d;
                    }
                    // A spot aimed away still gets a little budget: its cone edge may touch.
                    float spot = l.type == Light::Type::Spot
                                     ? 0.02f + l.spotFactor(glm::dot(l.direction, e.axis))
                                     : 1.0f;
                    weight = double(lum) * e.solidAngle * spot;
                }
                if (!(weight > 0)) continue;
                e.probability = float(weight);
                total += weight;
                targets_.push_back(e);
            }
        }
        for (auto& e : targets_) e.probability = float(e.probability / total);
        meanTargetRadius_ = 0.0f;
        for (const auto& t : targets) meanTargetRadius_ += t.radius / float(targets.size());
    }

    bool active() const { return !targets_.empty(); }
    float meanTargetRadius() const { return meanTargetRadius_; }

    // Samples a photon's origin, direction and power (already divided by `emitted`).
    bool sample(Rng& rng, long long emitted, glm::vec3& origin, glm::vec3& dir,
                glm::vec3& power) const {
        float u = rng.uniform(), acc = 0.0f;
        size_t k = targets_.size() - 1;
        for (size_t i = 0; i < targets_.size(); ++i) {
            acc += targets_[i].probability;
            if (u < acc) {
                k = i;
                break;
            }
        }
        const EmissionTarget& e = targets_[k];
        const PunctualLight& l = scene_.lights()[size_t(e.light)];
        glm::vec2 u2 = rng.uniform2();
        if (l.type == Light::Type::Directional) {
            Frame f(l.direction);
            glm::vec2 disk = sampleUniformDisk(u2) * e.radius;
            glm::vec3 q = e.centre + f.t * disk.x + f.b * disk.y;
            auto bounds = scene_.sceneBounds();
            float back = 2.0f * bounds.radius + glm::length(q - bounds.centre) + 1.0f;
            origin = q - l.direction * back;
            dir = l.direction;
            // Area density on the plane perpendicular to the light, over all disks of this light.
            float pdf = 0.0f;
            for (const auto& o : targets_) {
                if (o.light != e.light) continue;
                glm::vec3 c = o.centre - q;
                glm::vec3 perp = c - glm::dot(c, dir) * dir;
                if (glm::dot(perp, perp) <= o.radius * o.radius)
                    pdf += o.probability / (kPi * o.radius * o.radius);
            }
            if (!(pdf > 0)) return false;
            power = l.intensity / (float(emitted) * pdf);
            return true;
        }
        dir = e.cosMax <= -1.0f ? sampleUniformSphere(u2)
                                : Frame(e.axis).toWorld(sampleUniformCone(u2, e.cosMax));
        dir = glm::normalize(dir);
        float pdf = 0.0f;
        for (const auto& o : targets_) {
            if (o.light != e.light) continue;
            if (o.cosMax <= -1.0f || glm::dot(dir, o.axis) >= o.cosMax)
                pdf += o.probability / o.solidAngle;
        }
        float spot = l.spotFactor(glm::dot(l.direction, dir));
        if (!(pdf > 0) || spot <= 0) return false;
        origin = l.position;
        power = l.intensity * spot / (float(emitted) * pdf);
        return true;
    }

private:
    const RayTracingScene& scene_;
    std::vector<EmissionTarget> targets_;
    float meanTargetRadius_ = 0.0f;
};

// Orients the shading frame at a hit: opaque surfaces are two-sided (normals flipped to the side
// the ray came from); transmissive ones keep their outward normal to tell inside from outside.
void orientHit(SurfaceHit& hit, const glm::vec3& rayDir, bool transmissive) {
    if (!transmissive && glm::dot(hit.ng, rayDir) > 0) {
        hit.ng = -hit.ng;
        hit.ns = -hit.ns;
    }
}

// Traces photons of one pass; keeps those that reached a non-delta surface after >= 1 delta bounce.
std::vector<Photon> tracePhotons(const RayTracingScene& scene, const PhotonEmitter& emitter,
                                 long long count, uint64_t seed, int pass, int threads) {
    constexpr int kChunk = 4096;
    int chunks = int((count + kChunk - 1) / kChunk);
    std::vector<std::vector<Photon>> perChunk(static_cast<size_t>(chunks));
    parallelFor(chunks, threads, [&](int c) {
        auto& out = perChunk[size_t(c)];
        long long begin = (long long)c * kChunk, end = std::min(count, begin + kChunk);
        for (long long i = begin; i < end; ++i) {
            Rng rng(seed ^ kPhotonDomain, (uint64_t(pass) << 40) ^ uint64_t(i));
            glm::vec3 o, d, beta;
            if (!emitter.sample(rng, count, o, d, beta)) continue;
            const ShadingMaterial* medium = nullptr;
            int deltaBounces = 0;
            for (int depth = 0; depth < 32; ++depth) {
                SurfaceHit hit;
                if (!scene.intersect(o, d, std::numeric_limits<float>::infinity(), hit)) break;
                if (medium) beta *= beerLambert(medium->sigmaA, hit.t);
                // Light entering a translucent object is the path tracer's (its boundary has
                // no delta lobe that a caustic photon could follow).
                if (scene.medium(hit.geometry)) break;
                Bsdf bsdf(scene.bsdfParams(hit));
                orientHit(hit, d, bsdf.isTransmissive());
                if (deltaBounces > 0 && bsdf.hasNonDelta()) {
                    glm::vec3 facing = glm::dot(hit.ng, d) < 0 ? hit.ng : -hit.ng;
                    out.push_back(Photon{hit.p, -d, facing, beta});
                }
                if (!bsdf.hasDelta()) break;
                Frame frame(hit.ns);
                Bsdf::Sample s;
                float uLobe = rng.uniform();
                if (!bsdf.sample(frame.toLocal(-d), uLobe, rng.uniform2(),
                                 TransportMode::Importance, s))
                    break;
                if (!s.delta) break;  // light leaving through a non-delta lobe is the path tracer's
                glm::vec3 wi = frame.toWorld(s.wi);
                // Reject directions on the wrong side of the true surface (shading-normal leaks).
                if (s.transmitted == (glm::dot(wi, hit.ng) * glm::dot(-d, hit.ng) > 0)) break;
                beta *= s.weight;
                ++deltaBounces;
                if (s.transmitted) {
                    const ShadingMaterial& m = scene.material(hit);
                    medium = glm::dot(wi, hit.ng) < 0 && m.hasVolume ? &m : nullptr;
                }
                if (!(maxComponent(beta) > 0) || !isFiniteVec(beta)) break;
                o = spawnOrigin(hit, wi);
                d = wi;
            }
        }
    });
    std::vector<Photon> all;
    size_t total = 0;
    for (const auto& v : perChunk) total += v.size();
    all.reserve(total);
    for (auto& v : perChunk) all.insert(all.end(), v.begin(), v.end());
    return all;
}

// ---- camera paths -------------------------------------------------------------------------------

struct PathContext {
    const RayTracingScene& scene;
    const PhotonMap* photons;  // null or empty: no caustic gathering
    int maxDepth;
    MediumScattering scattering = MediumScattering::Multiple;
};

constexpr float kInvFourPi = 1.0f / (4.0f * kPi);
// Steps of one delta or ratio tracking walk, and scattering events of one path, before giving
// up (only reached by media far thicker than any mirage scene's; Russian roulette ends paths).
constexpr int kMaxTrackingSteps = 1 << 16;
constexpr int kMaxMediumEvents = 1 << 16;

// Fresnel reflectance of a translucent object's boundary for a ray crossing it at |cos| =
// `cosAbs` to the normal. The boundary does not bend light, so the outside angle is the ray's
// angle either way and the same value holds both ways (reciprocal, no total internal reflection).
float boundaryReflectance(const Medium& m, float cosAbs) {
    return m.ior == 1.0f ? 0.0f : fresnelDielectric(std::clamp(cosAbs, 0.0f, 1.0f), m.ior);
}

// Delta tracking (Woodcock): the distance of the first real collision along o + t d (d unit)
// before tMax, or false when the ray reaches tMax unscattered.
bool deltaTrack(const Medium& m, const glm::vec3& o, const glm::vec3& d, float tMax, Rng& rng,
                float& tOut) {
    if (!(m.majorant > 0)) return false;
    float t = 0.0f;
    for (int i = 0; i < kMaxTrackingSteps; ++i) {
        t -= std::log(1.0f - rng.uniform()) / m.majorant;
        if (!(t < tMax)) return false;
        if (m.homogeneous() || rng.uniform() * m.majorant < m.sigmaT(o + t * d)) {
            tOut = t;
            return true;
        }
    }
    return false;
}

// Transmittance over [0, tMax) along o + t d: exact for a homogeneous medium, ratio tracking
// (Novak et al. 2014) for a density grid.
float mediumTransmittance(const Medium& m, const glm::vec3& o, const glm::vec3& d, float tMax,
                          Rng& rng) {
    if (!(m.majorant > 0)) return 1.0f;
    if (!std::isfinite(tMax)) return 0.0f;
    if (m.homogeneous()) return std::exp(-m.extinction * tMax);
    float T = 1.0f, t = 0.0f;
    for (int i = 0; i < kMaxTrackingSteps; ++i) {
        t -= std::log(1.0f - rng.uniform()) / m.majorant;
        if (!(t < tMax)) return T;
        T *= std::max(0.0f, 1.0f - m.sigmaT(o + t * d) / m.majorant);
        if (T < 0.05f) {  // Russian roulette on small transmittance: unbiased
            if (rng.uniform() < 0.5f) return 0.0f;
            T *= 2.0f;
        }
    }
    return T;
}

// Visibility of a shadow ray from o along unit d over (0, tMax), starting inside `inside` (or
// outside every medium): 0 behind an opaque surface or glass (caustics are the photon map's),
// through translucent objects the product of their boundaries' Fresnel transmittance and their
// media's transmittance. Without translucent objects it is the plain occlusion test.
float shadowTransmittance(const RayTracingScene& scene, glm::vec3 o, const glm::vec3& d, float tMax,
                          const Medium* inside, Rng& rng) {
    if (!scene.hasMedia()) return scene.occluded(o, d, tMax) ? 0.0f : 1.0f;
    float T = 1.0f;
    for (int crossing = 0; crossing < 64; ++crossing) {
        SurfaceHit h;
        const bool found = scene.intersect(o, d, tMax, h);
        const float segment = found ? h.t : tMax;
        if (inside) T *= mediumTransmittance(*inside, o, d, segment, rng);
        if (!found || !(T > 0)) return found ? 0.0f : T;
        const Medium* m = scene.medium(h.geometry);
        if (!m) return 0.0f;
        T *= 1.0f - boundaryReflectance(*m, std::abs(glm::dot(d, h.ng)));
        inside = glm::dot(d, h.ng) < 0 ? m : nullptr;
        const glm::vec3 previous = o;
        o = spawnOrigin(h, d);
        if (std::isfinite(tMax)) tMax = std::max(0.0f, tMax - glm::length(o - previous));
        if (!(tMax > 0)) return T;
    }
    return 0.0f;
}

// Light scattered towards the camera path at a medium point x (isotropic phase 1/4pi): every
// punctual light and one environment sample, each through shadowTransmittance. `mis`: the path
// continues by phase sampling, so the environment sample is weighted against it.
glm::vec3 mediumDirectLight(const RayTracingScene& scene, const glm::vec3& x, const Medium& m,
                            Rng& rng, bool mis) {
    glm::vec3 L(0.0f);
    for (const PunctualLight& l : scene.lights()) {
        glm::vec3 wi, Li;
        float dist;
        if (l.type == Light::Type::Directional) {
            wi = -l.direction;
            dist = std::numeric_limits<float>::infinity();
            Li = l.intensity;
        } else {
            glm::vec3 v = l.position - x;
            float d2 = glm::dot(v, v);
            if (!(d2 > 0)) continue;
            dist = std::sqrt(d2);
            wi = v / dist;
            Li = l.intensity * (l.spotFactor(glm::dot(l.direction, -wi)) / d2);
        }
        if (maxComponent(Li) <= 0) continue;
        float T = shadowTransmittance(scene, x, wi,
                                      std::isfinite(dist) ? dist * (1.0f - 1e-4f) : dist, &m, rng);
        L += Li * (T * kInvFourPi);
    }
    if (const EnvironmentLight* env = scene.environment()) {
        glm::vec3 wi;
        float pdfL;
        glm::vec3 Le = env->sample(rng.uniform2(), wi, pdfL);
        if (pdfL > 0 && maxComponent(Le) > 0) {
            float T =
                shadowTransmittance(scene, x, wi, std::numeric_limits<float>::infinity(), &m, rng);
            float w = mis ? powerHeuristic(pdfL, kInvFourPi) : 1.0f;
            L += Le * (T * kInvFourPi * w / pdfL);
        }
    }
    return L;
}

glm::vec3 gatherPhotons(const PhotonMap& map, const Bsdf& bsdf, const Frame& frame,
                        const glm::vec3& woLocal, const SurfaceHit& hit) {
    glm::vec3 sum(0.0f);
    map.forEachNear(hit.p, [&](const Photon& ph) {
        // Photons on another surface within the radius (a corner, the far side of a thin wall)
        // would leak light; keep those on (nearly) the same plane.
        if (std::abs(glm::dot(ph.normal, hit.ng)) < 0.7f) return;
        sum += bsdf.eval(woLocal, frame.toLocal(ph.wi), TransportMode::Radiance) * ph.power;
    });
    float r = map.radius();
    return sum / (kPi * r * r);
}

// Adds to L the light of the scene's punctual lights reflected at `hit` towards wo (local
// frame) times the path throughput beta, each light's visibility through glass and translucent
// media included.
void addPunctualLight(const RayTracingScene& scene, const SurfaceHit& hit, const Bsdf& bsdf,
                      const Frame& frame, const glm::vec3& wo, const Medium* volume,
                      const glm::vec3& beta, Rng& rng, glm::vec3& L) {
    for (const PunctualLight& l : scene.lights()) {
        glm::vec3 wi;
        float dist;
        glm::vec3 Li;
        if (l.type == Light::Type::Directional) {
            wi = -l.direction;
            dist = std::numeric_limits<float>::infinity();
            Li = l.intensity;
        } else {
            glm::vec3 v = l.position - hit.p;
            float d2 = glm::dot(v, v);
            if (!(d2 > 0)) continue;
            dist = std::sqrt(d2);
            wi = v / dist;
            Li = l.intensity * (l.spotFactor(glm::dot(l.direction, -wi)) / d2);
        }
        if (maxComponent(Li) <= 0) continue;
        glm::vec3 wiLocal = frame.toLocal(wi);
        glm::vec3 f = bsdf.eval(wo, wiLocal, TransportMode::Radiance);
        if (maxComponent(f) <= 0) continue;
        glm::vec3 so = spawnOrigin(hit, wi);
        const float T = shadowTransmittance(
            scene, so, wi,
            std::isfinite(dist) ? glm::length(l.position - so) * (1.0f - 1e-4f) : dist, volume,
            rng);
        if (!(T > 0)) continue;
        L += beta * f * std::abs(wiLocal.z) * Li * T;
    }
}

// Radiance along one camera ray. `firstHitVirtual` reports whether the first surface is virtual.
glm::vec3 tracePath(const PathContext& ctx, glm::vec3 o, glm::vec3 d, Rng& rng,
                    bool& firstHitVirtual) {
    const RayTracingScene& scene = ctx.scene;
    const EnvironmentLight* env = scene.environment();
    glm::vec3 L(0.0f), beta(1.0f);
    bool deltaBounce = true;  // the camera ray counts as delta: no MIS for what it hits directly
    float prevPdf = 0.0f;
    const ShadingMaterial* medium = nullptr;
    const Medium* volume = nullptr;  // the translucent object's medium the path is inside
    int mediumEvents = 0;
    firstHitVirtual = false;
    for (int depth = 0; depth < ctx.maxDepth; ++depth) {
        SurfaceHit hit;
        const bool found = scene.intersect(o, d, std::numeric_limits<float>::infinity(), hit);
        if (depth == 0 && found) firstHitVirtual = scene.origin(hit) == Origin::Virtual;
        if (volume) {
            if (!found) break;  // leaked out of a mesh that is not closed
            float t;
            if (deltaTrack(*volume, o, d, hit.t, rng, t)) {
                // A real collision: scatter (albedo weights the survival of the photon).
                if (ctx.scattering == MediumScattering::Single && mediumEvents > 0) break;
                if (++mediumEvents > kMaxMediumEvents) break;
                --depth;  // medium events do not count as surface vertices
                const glm::vec3 x = o + t * d;
                beta *= volume->albedo;
                const bool single = ctx.scattering == MediumScattering::Single;
                L += beta * mediumDirectLight(scene, x, *volume, rng, !single);
                if (single) break;
                if (mediumEvents > 32) {
                    float q = std::max(0.02f, 1.0f - maxComponent(beta));
                    if (rng.uniform() < q) break;
                    beta /= 1.0f - q;
                }
                if (!(maxComponent(beta) > 0)) break;
                d = sampleUniformSphere(rng.uniform2());
                o = x;
                deltaBounce = false;
                prevPdf = kInvFourPi;
                continue;
            }
        }
        if (!found) {
            if (env) {
                glm::vec3 Le = env->radiance(d);
                float w = deltaBounce ? 1.0f : powerHeuristic(prevPdf, env->pdf(d));
                L += beta * Le * w;
            }
            break;
        }
        if (medium) beta *= beerLambert(medium->sigmaA, hit.t);
        if (const Medium* boundary = scene.medium(hit.geometry)) {
            // A translucent object's boundary: Fresnel reflection (delta) or straight passage.
            const float cosI = glm::dot(d, hit.ng);
            if (rng.uniform() < boundaryReflectance(*boundary, std::abs(cosI))) {
                glm::vec3 wi = d - 2.0f * cosI * hit.ng;
                deltaBounce = true;
                o = spawnOrigin(hit, wi);
                d = wi;
            } else {
                // Passing straight on keeps the direction, so the MIS state of the vertex that
                // chose it (deltaBounce, prevPdf) still applies where the ray ends.
                volume = cosI < 0 ? boundary : nullptr;
                o = spawnOrigin(hit, d);
            }
            continue;
        }
        L += beta * scene.emission(hit);  // area emitters are found by BSDF sampling only

        Bsdf bsdf(scene.bsdfParams(hit));
        orientHit(hit, d, bsdf.isTransmissive());
        Frame frame(hit.ns);
        glm::vec3 wo = frame.toLocal(-d);

        if (bsdf.hasNonDelta()) {
            // Direct light from punctual lights (delta lights: no MIS).
            addPunctualLight(scene, hit, bsdf, frame, wo, volume, beta, rng, L);
            // Environment: light sample with MIS against BSDF sampling.
            if (env) {
                glm::vec3 wi;
                float pdfL;
                glm::vec3 Le = env->sample(rng.uniform2(), wi, pdfL);
                if (pdfL > 0 && maxComponent(Le) > 0) {
                    glm::vec3 wiLocal = frame.toLocal(wi);
                    glm::vec3 f = bsdf.eval(wo, wiLocal, TransportMode::Radiance);
                    const float T = maxComponent(f) > 0
                                        ? shadowTransmittance(
                                              scene, spawnOrigin(hit, wi), wi,
                                              std::numeric_limits<float>::infinity(), volume, rng)
                                        : 0.0f;
                    if (T > 0) {
                        float w = powerHeuristic(pdfL, bsdf.pdf(wo, wiLocal));
                        L += beta * f * std::abs(wiLocal.z) * Le * (T * w / pdfL);
                    }
                }
            } else {
                (void)rng.uniform2();  // keep the random stream layout independent of the scene
            }
            if (ctx.photons && !ctx.photons->empty())
                L += beta * gatherPhotons(*ctx.photons, bsdf, frame, wo, hit);
        }

        Bsdf::Sample s;
        float uLobe = rng.uniform();
        if (!bsdf.sample(wo, uLobe, rng.uniform2(), TransportMode::Radiance, s)) break;
        glm::vec3 wi = frame.toWorld(s.wi);
        // A reflection must leave on the side it arrived from, a transmission on the other side
        // (shading normals can disagree with the true surface).
        if (s.transmitted == (glm::dot(wi, hit.ng) * glm::dot(-d, hit.ng) > 0)) break;
        beta *= s.weight;
        deltaBounce = s.delta;
        prevPdf = s.pdf;
        if (s.transmitted) {
            const ShadingMaterial& m = scene.material(hit);
            medium = glm::dot(wi, hit.ng) < 0 && m.hasVolume ? &m : nullptr;
        }
        if (depth >= 3) {
            float q = std::max(0.05f, 1.0f - maxComponent(beta));
            if (rng.uniform() < q) break;
            beta /= 1.0f - q;
        }
        if (!(maxComponent(beta) > 0)) break;
        o = spawnOrigin(hit, wi);
        d = wi;
    }
    return L;
}

}  // namespace

RenderCamera cameraFromNode(const Scene& scene, const std::string& nodeName, int width,
                            int height) {
    if (width <= 0 || height <= 0)
        throw Error("render: image size must be positive (got " + std::to_string(width) + "x" +
                    std::to_string(height) + ")");
    int found = -1;
    std::string names;
    for (size_t i = 0; i < scene.nodes.size(); ++i) {
        const Node& n = scene.nodes[i];
        if (n.camera < 0) continue;
        names += (names.empty() ? "" : ", ") + ("'" + n.name + "'");
        if (n.name == nodeName && found < 0) found = int(i);
    }
    if (found < 0)
        throw Error("scene '" + scene.source.string() + "' has no camera node '" + nodeName +
                    "'; camera nodes: " +
                    (names.empty() ? std::string("none (add a glTF camera node)") : names));
    const Node& node = scene.nodes[size_t(found)];
    if (node.camera >= int(scene.cameras.size()))
        throw Error("scene camera node '" + nodeName + "': camera index out of range");
    const CameraNodeInfo& cam = scene.cameras[size_t(node.camera)];
    if (!(cam.yfov > 0.0f && cam.yfov < kPi))
        throw Error("scene camera '" + nodeName + "': yfov must be in (0, pi) radians");
    RenderCamera rc;
    rc.intrinsics.width = width;
    rc.intrinsics.height = height;
    rc.intrinsics.fy = 0.5 * height / std::tan(0.5 * double(cam.yfov));
    rc.intrinsics.fx = rc.intrinsics.fy;
    rc.intrinsics.cx = 0.5 * width - 0.5;
    rc.intrinsics.cy = 0.5 * height - 0.5;
    rc.intrinsics.model = DistortionModel::BrownConrady;
    // glTF cameras look down -Z with +Y up; convert to OpenCV camera axes.
    rc.T_world_camera = Pose::fromMatrix(node.world) * kCvFromGltfCamera;
    return rc;
}

RenderResult render(const RayTracingScene& scene, const RenderCamera& camera,
                    const RenderSettings& settings, const ProgressCallback& progress) {
    const int width = camera.intrinsics.width, height = camera.intrinsics.height;
    if (width <= 0 || height <= 0 || !camera.intrinsics.isValid())
        throw Error("render: invalid camera intrinsics (size " + std::to_string(width) + "x" +
                    std::to_string(height) + ")");
    if (!camera.T_world_camera.isFinite()) throw Error("render: camera pose is not finite");
    if (settings.samplesPerPixel <= 0) throw Error("render: samples per pixel must be >= 1");
    int threads = settings.threads > 0 ? settings.threads
                                       : int(std::max(1u, std::thread::hardware_concurrency()));

    // Camera rays are per pixel position only; precompute nothing (unproject is cheap enough
    // next to path tracing), but the rotation once.
    const glm::mat3 R(camera.T_world_camera.rotationMatrix());
    const glm::vec3 camPos(camera.T_world_camera.translation);

    PhotonEmitter emitter(scene);
    const bool usePhotons = settings.caustics && emitter.active();
    long long photonsPerPass = settings.photonsPerPass > 0
                                   ? settings.photonsPerPass
                                   : std::max<long long>(20000, (long long)width * height / 2);
    float r1 = settings.initialPhotonRadius > 0
                   ? settings.initialPhotonRadius
                   : 0.1f * std::max(emitter.meanTargetRadius(), 1e-3f);

    const size_t pixels = size_t(width) * size_t(height);
    std::vector<glm::dvec3> sum(pixels, glm::dvec3(0.0));
    std::vector<uint32_t> virtualHits(pixels, 0);
    std::atomic<long long> nonFinite{0};
    RenderResult result;
    const int tilesX = (width + kTile - 1) / kTile, tilesY = (height + kTile - 1) / kTile;
    const bool rowSubset = !settings.rows.empty();
    const int stripsPerRow = (width + kTile * kTile - 1) / (kTile * kTile);
    for (size_t i = 0; i < settings.rows.size(); ++i)
        if (settings.rows[i] < 0 || settings.rows[i] >= height ||
            (i > 0 && settings.rows[i] <= settings.rows[i - 1]))
            throw Error("render: rows must be ascending and inside the image (0 to " +
                        std::to_string(height - 1) + ")");
    auto start = std::chrono::steady_clock::now();
    float radius2 = r1 * r1;

    int pass = 0;
    for (; pass < settings.samplesPerPixel; ++pass) {
        PhotonMap photonMap;
        if (usePhotons) {
            auto photons =
                tracePhotons(scene, emitter, photonsPerPass, settings.seed, pass, threads);
            result.photonsStored += (long long)photons.size();
            photonMap = PhotonMap(std::move(photons), std::sqrt(radius2));
        }
        PathContext ctx{scene, usePhotons ? &photonMap : nullptr, settings.maxDepth,
                        settings.mediumScattering};
        // Work items: square tiles, or for a subset of rows, strips of one row and kTile^2 pixels.
        const int items = rowSubset ? int(settings.rows.size()) * stripsPerRow : tilesX * tilesY;
        parallelFor(items, threads, [&](int item) {
            int x0, y0, x1, y1;
            if (rowSubset) {
                y0 = settings.rows[size_t(item / stripsPerRow)];
                y1 = y0 + 1;
                x0 = (item % stripsPerRow) * kTile * kTile;
                x1 = std::min(width, x0 + kTile * kTile);
            } else {
                x0 = (item % tilesX) * kTile;
                y0 = (item / tilesX) * kTile;
                x1 = std::min(width, x0 + kTile);
                y1 = std::min(height, y0 + kTile);
            }
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x) {
                    size_t idx = size_t(y) * size_t(width) + size_t(x);
                    Rng rng(settings.seed, (uint64_t(pass) << 40) ^ uint64_t(idx));
                    glm::vec2 jitter = rng.uniform2();
                    // OpenCV pixel (x, y) covers [x - 0.5, x + 0.5) x [y - 0.5, y + 0.5).
                    auto dirCam =
                        camera.intrinsics.unproject({x + jitter.x - 0.5, y + jitter.y - 0.5});
                    if (!dirCam) continue;
                    glm::vec3 d = glm::normalize(R * glm::vec3(*dirCam));
                    bool virt = false;
                    glm::vec3 L = tracePath(ctx, camPos, d, rng, virt);
                    if (!isFiniteVec(L)) {
                        ++nonFinite;
                        continue;
                    }
                    sum[idx] += glm::dvec3(L);
                    virtualHits[idx] += virt ? 1u : 0u;
                }
        });
        // Knaus & Zwicker 2011: r_{i+1}^2 = r_i^2 (i + alpha) / (i + 1).
        radius2 *= (float(pass + 1) + settings.radiusAlpha) / float(pass + 2);
        double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (progress) progress(pass + 1, settings.samplesPerPixel, elapsed);
        if (settings.maxSeconds > 0 && elapsed >= settings.maxSeconds) {
            ++pass;
            break;
        }
    }
    result.passes = pass;
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.nonFiniteSamples = nonFinite;
    result.radiance.create(height, width, CV_32FC3);
    result.virtualCoverage.create(height, width, CV_32F);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            size_t idx = size_t(y) * size_t(width) + size_t(x);
            glm::dvec3 v = sum[idx] / double(pass);
            result.radiance.at<cv::Vec3f>(y, x) = {float(v.x), float(v.y), float(v.z)};
            result.virtualCoverage.at<float>(y, x) = float(virtualHits[idx]) / float(pass);
        }
    return result;
}

}  // namespace mirage::raytrace
