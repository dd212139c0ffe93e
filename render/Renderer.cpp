#include "render/Renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>
#include <opencv2/imgproc.hpp>

#include "core/Error.h"
#include "render/FrameImports.h"
#include "render/PassRegistry.h"
#include "render/governor/GovernedKnobs.h"
#include "render/passes/composite/CompositePass.h"
#include "render/passes/environment/EnvironmentPass.h"
#include "render/passes/ism/IsmPass.h"
#include "render/passes/vpl/VplPass.h"

namespace mirage::render {
namespace {

// The camera's clip planes, metres from the camera: a tabletop at 1 cm, a room's far wall well
// inside 100 m (the depth buffer is 32-bit float).
constexpr float kNearM = 0.01f, kFarM = 100.0f;

// Does the sphere touch the light's cone of influence (spot cone, range)?
bool inLightCone(const SceneLight& l, const BoundingSphere& s) {
    if (l.type == kLightDirectional) return true;
    const glm::vec3 d = s.center - l.position;
    const float dist = glm::length(d);
    if (dist <= s.radius) return true;
    if (l.range > 0.0f && dist - s.radius > l.range) return false;
    if (l.type == kLightPoint) return true;
    const float angle = std::acos(std::clamp(glm::dot(d / dist, l.direction), -1.0f, 1.0f));
    const float halfAngle = std::asin(std::clamp(s.radius / dist, 0.0f, 1.0f));
    return angle - halfAngle <= l.outerAngle;
}

// Sphere against the six planes of a view-projection frustum (Gribb & Hartmann).
bool inFrustum(const glm::mat4& vp, const BoundingSphere& s) {
    const glm::mat4 m = glm::transpose(vp);
    const glm::vec4 planes[6] = {m[3] + m[0], m[3] - m[0], m[3] + m[1],
                                 m[3] - m[1], m[3] + m[2], m[3] - m[2]};
    for (const glm::vec4& p : planes) {
        const float len = glm::length(glm::vec3(p));
        if (len <= 0) continue;
        if ((glm::dot(glm::vec3(p), s.center) + p.w) / len < -s.radius) return false;
    }
    return true;
}

// Slopes a/z of the two planes through the camera centre (containing the other image axis) that
// touch a sphere whose centre is (ca, cz) in the a-z plane of the camera frame: the sphere's exact
// extent along image axis a. False when the sphere reaches the camera plane (z <= r): unbounded.
bool tangentSlopes(double ca, double cz, double r, double& lo, double& hi) {
    const double a = cz * cz - r * r;
    if (cz <= r || a <= 1e-9) return false;
    const double root = r * std::sqrt(ca * ca + a);
    lo = (ca * cz - root) / a;
    hi = (ca * cz + root) / a;
    return true;
}

// The canvas pixels (GL window rectangle x, y, width, height; GL row 0 = image row 0, see
// CameraProjection::projectionMatrix) that can show one draw: the exact projection of its
// bounding sphere, 2 px margin. The whole canvas when the sphere reaches the camera plane; width
// 0 when it is outside the frustum. Conservative: every fragment of a draw lies inside its
// bounding sphere.
glm::ivec4 sphereRect(const BoundingSphere& b, const glm::mat4& view, const glm::mat4& viewProj,
                      const CameraProjection& p) {
    const int width = p.canvasWidth, height = p.canvasHeight;
    if (!inFrustum(viewProj, b)) return {0, 0, 0, 0};
    const glm::dvec3 c(view * glm::vec4(b.center, 1.0f));  // camera frame (OpenCV axes)
    const double r = double(b.radius) * 1.001 + 1e-5;      // float rounding of the bounds
    double sx0, sx1, sy0, sy1;
    if (!tangentSlopes(c.x, c.z, r, sx0, sx1) || !tangentSlopes(c.y, c.z, r, sy0, sy1))
        return {0, 0, width, height};
    // Window position of slope m: fx m + cx + 0.5 (pixel centres at +0.5).
    const int x0 = std::clamp(int(std::floor(p.camera.fx * sx0 + p.canvasCx)) - 2, 0, width);
    const int y0 = std::clamp(int(std::floor(p.camera.fy * sy0 + p.canvasCy)) - 2, 0, height);
    const int x1 = std::clamp(int(std::ceil(p.camera.fx * sx1 + p.canvasCx)) + 3, 0, width);
    const int y1 = std::clamp(int(std::ceil(p.camera.fy * sy1 + p.canvasCy)) + 3, 0, height);
    return {x0, y0, x1 - x0, y1 - y0};
}

// FrameContext's specularScissor (the bounding rectangle of every specular draw's), its
// specularRects and refractiveRects (the glass draws'), and its translucentRects.
void specularRectangles(const GpuScene& s, const glm::mat4& view, const glm::mat4& viewProj,
                        const CameraProjection& p, FrameContext& c) {
    std::vector<glm::ivec4> all, glass;
    for (int i : s.specularDraws()) {
        const DrawItem& d = s.draws()[size_t(i)];
        const glm::ivec4 r = sphereRect(d.bounds, view, viewProj, p);
        if (r.z <= 0 || r.w <= 0) continue;
        all.push_back(r);
        if (d.transmissive) glass.push_back(r);
    }
    c.specularScissor = {0, 0, 0, 0};
    if (!all.empty()) {
        glm::ivec2 lo(all.front().x, all.front().y), hi = lo;
        for (const glm::ivec4& r : all) {
            lo = glm::min(lo, glm::ivec2(r.x, r.y));
            hi = glm::max(hi, glm::ivec2(r.x + r.z, r.y + r.w));
        }
        c.specularScissor = {lo.x, lo.y, hi.x - lo.x, hi.y - lo.y};
    }
    if (!c.options.specular.rectsPerObject) {
        const bool any = !all.empty(), anyGlass = !glass.empty();
        all.assign(any ? 1 : 0, c.specularScissor);
        glass.assign(anyGlass ? 1 : 0, c.specularScissor);
    }
    c.specularRects = mergeOverlappingRects(std::move(all));
    c.refractiveRects = mergeOverlappingRects(std::move(glass));
    c.glassSpecularRects.clear();
    c.mirrorRects.clear();
    for (const glm::ivec4& r : c.specularRects)
        (std::any_of(c.refractiveRects.begin(), c.refractiveRects.end(),
                     [&](const glm::ivec4& g) { return rectsOverlap(r, g); })
             ? c.glassSpecularRects
             : c.mirrorRects)
            .push_back(r);
    std::vector<glm::ivec4> translucent;
    for (const DrawItem& d : s.draws()) {
        if (!d.translucent) continue;
        const glm::ivec4 r = sphereRect(d.bounds, view, viewProj, p);
        if (r.z > 0 && r.w > 0) translucent.push_back(r);
    }
    c.translucentRects = mergeOverlappingRects(std::move(translucent));
}

// The smallest sphere holding both.
BoundingSphere mergeSpheres(const BoundingSphere& a, const BoundingSphere& b) {
    const glm::vec3 d = b.center - a.center;
    const float dist = glm::length(d);
    if (dist + b.radius <= a.radius) return a;
    if (dist + a.radius <= b.radius) return b;
    BoundingSphere m;
    m.radius = 0.5f * (dist + a.radius + b.radius);
    m.center = a.center + d * ((m.radius - a.radius) / std::max(dist, 1e-12f));
    return m;
}

float luminance(const glm::vec3& c) {
    return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

glm::vec3 anyPerpendicular(const glm::vec3& d) {
    return std::abs(d.y) < 0.99f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
}

// A spot light whose cone holds a mirror or glass object gets photon G-buffers (caustics on):
// their layer, the frustum fitted to the objects' bounding sphere, and the plan's peak
// irradiance.
void planCaustics(const SceneLight& l, const GpuScene& s, bool causticsOn, LightPlan& lp,
                  FramePlan& plan) {
    BoundingSphere specBounds;
    bool specularInCone = false;
    for (int di : s.specularDraws()) {
        const BoundingSphere& b = s.draws()[size_t(di)].bounds;
        if (!inLightCone(l, b)) continue;
        specBounds = specularInCone ? mergeSpheres(specBounds, b) : b;
        specularInCone = true;
    }
    if (l.type == kLightSpot && specularInCone && causticsOn) {
        lp.caustics = true;
        lp.causticLayer = plan.causticLayers++;
        const float d = glm::length(specBounds.center - l.position);
        const float radius = std::max(specBounds.radius * 1.02f, 1e-4f);
        const float peak = luminance(l.radiantIntensity);
        if (d > radius) {
            // Fitted to the objects: every texel falls on (or near) them.
            const float half = std::asin(std::min(radius / d, 0.999f));
            const glm::vec3 axis = (specBounds.center - l.position) / d;
            lp.causticTanHalf = std::tan(half);
            lp.causticViewProj =
                glm::perspective(2.0f * half, 1.0f, std::max((d - radius) * 0.5f, 1e-3f),
                                 d + radius * 1.5f) *
                glm::lookAt(l.position, specBounds.center, anyPerpendicular(axis));
            plan.causticIrradiance =
                std::max(plan.causticIrradiance, peak / std::max(d * d, 1e-4f));
        } else {
            // The light inside the objects' bounds: the spot's own frustum.
            const float half = std::min(l.outerAngle * 1.02f + 0.01f, 1.48f);
            lp.causticTanHalf = std::tan(half);
            lp.causticViewProj =
                glm::perspective(2.0f * half, 1.0f, 1e-3f, 2.0f * radius + 1e-2f) *
                glm::lookAt(l.position, l.position + l.direction, anyPerpendicular(l.direction));
            plan.causticIrradiance =
                std::max(plan.causticIrradiance, peak / std::max(radius * radius * 0.01f, 1e-4f));
        }
    }
}

// The light's shadow-map matrices (spot: its cone; point: six cube faces; directional: an
// orthographic box around the scene's bounds B of radius R) into its GpuLight, and its layers.
void shadowMatrices(const SceneLight& l, const BoundingSphere& B, float R, GpuLight& g,
                    LightPlan& lp) {
    g.position = l.position;
    g.range = l.range;
    g.direction = l.direction;
    g.type = l.type;
    const float scale = 1.0f / std::max(0.001f, l.cosInner - l.cosOuter);
    g.cosOuter = l.cosOuter;
    g.cosInner = l.cosInner;
    g.coneScale = scale;
    g.coneOffset = -l.cosOuter * scale;
    g.radiantIntensity = l.radiantIntensity;
    g.frustumSize = 1.0f;
    const float farL = glm::length(B.center - l.position) + R + 0.1f;
    const float nearL = std::clamp(farL * 1e-4f, 0.005f, 0.05f);
    if (l.type == kLightSpot) {
        const float half = std::min(l.outerAngle * 1.02f + 0.01f, 1.48f);
        g.frustumSize = std::tan(half);
        g.viewProj[0] =
            glm::perspective(2.0f * half, 1.0f, nearL, farL) *
            glm::lookAt(l.position, l.position + l.direction, anyPerpendicular(l.direction));
        lp.layers = 1;
    } else if (l.type == kLightPoint) {
        const glm::vec3 dirs[6] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                   {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
        const glm::vec3 ups[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1},
                                  {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
        g.frustumSize = 1.0f;
        for (int f = 0; f < 6; ++f)
            g.viewProj[f] = glm::perspective(glm::half_pi<float>(), 1.0f, nearL, farL) *
                            glm::lookAt(l.position, l.position + dirs[f], ups[f]);
        lp.layers = 6;
    } else {
        const glm::vec3 eye = B.center - l.direction * (2.0f * R + 1.0f);
        g.position = eye;
        g.range = 0.0f;
        g.frustumSize = R;
        g.viewProj[0] = glm::ortho(-R, R, -R, R, 0.0f, 4.0f * R + 2.0f) *
                        glm::lookAt(eye, B.center, anyPerpendicular(l.direction));
        lp.layers = 1;
    }
}

// A group of virtual draws that share a focused virtual-occluder map, with their bounds.
struct FocusGroup {
    std::vector<int> draws;
    std::vector<BoundingSphere> spheres;
    float size = 0.0f;  // tan of the half angle (spot, point) or the half extent (directional, m)
    glm::mat4 viewProj{1.0f};
};

// The focused map's frustum from light l around `spheres`: spot and point lights, a square
// perspective frustum about the direction to their merged bounds, wide enough for each sphere's
// bounding cone; directional lights, an orthographic box around the merged bounds. False when a
// sphere holds the light (no frustum from inside) or the frustum would be wider than 2 x 1.2 rad.
bool fitFocus(const SceneLight& l, const std::vector<BoundingSphere>& spheres, float& size,
              glm::mat4& viewProj) {
    BoundingSphere all = spheres.front();
    for (const BoundingSphere& b : spheres) all = mergeSpheres(all, b);
    const float radius = std::max(all.radius * 1.02f, 1e-3f);
    if (l.type == kLightDirectional) {
        const glm::vec3 eye = all.center - l.direction * (radius + 0.1f);
        size = radius;
        viewProj = glm::ortho(-radius, radius, -radius, radius, 0.0f, 2.0f * radius + 0.2f) *
                   glm::lookAt(eye, all.center, anyPerpendicular(l.direction));
        return true;
    }
    const glm::vec3 toCentre = all.center - l.position;
    const float dist = glm::length(toCentre);
    if (dist <= radius) return false;
    const glm::vec3 axis = toCentre / dist;
    float half = 0.0f, nearest = dist - radius;
    for (const BoundingSphere& b : spheres) {
        const glm::vec3 v = b.center - l.position;
        const float d = glm::length(v);
        const float r = b.radius * 1.02f + 1e-3f;
        if (d <= r) return false;
        const float off = std::acos(std::clamp(glm::dot(v / d, axis), -1.0f, 1.0f));
        half = std::max(half, off + std::asin(std::min(r / d, 1.0f)));
        nearest = std::min(nearest, d - r);
    }
    if (half > 1.2f) return false;
    size = std::tan(half);
    viewProj =
        glm::perspective(2.0f * half, 1.0f, std::max(nearest * 0.5f, 1e-3f), dist + radius * 1.5f) *
        glm::lookAt(l.position, all.center, anyPerpendicular(axis));
    return true;
}

// The virtual occluders' own shadow maps (LightPlan::focusDraws) for the virtual draws that go
// into light l's occluder maps (ShadowPass::drawOccluders' choice). Glass there is opaque only
// because this light's caustics carry the light through it (or glass shadows are off): it stays
// in the light's own map (LightPlan::unfocusedDraws). The others are grouped so that each
// group's frustum is small: every draw starts as its own group, and the two groups whose merged
// frustum is smallest are merged while there are more than kMaxFocusMaps or the merge widens the
// larger frustum by at most 25 % (one raster for neighbours). Used only where every frustum is
// at most half the light's own (else one map of all occluders is nearly as fine). Quadratic in
// the virtual draws per merge: meant for the handful a tabletop holds.
void planVirtualFocus(const SceneLight& l, const GpuScene& s, LightPlan& lp, GpuLight& g) {
    std::vector<FocusGroup> groups;
    std::vector<int> unfocused;
    for (size_t i = 0; i < s.draws().size(); ++i) {
        const DrawItem& d = s.draws()[i];
        if (d.origin != Origin::Virtual || !inLightCone(l, d.bounds)) continue;
        if (lp.glassTransmits && d.transmissive) continue;  // in the glass layer instead
        if (lp.translucentTransmits && d.translucent) continue;
        if (d.transmissive) {
            unfocused.push_back(int(i));
            continue;
        }
        FocusGroup f;
        f.draws = {int(i)};
        f.spheres = {d.bounds};
        if (!fitFocus(l, f.spheres, f.size, f.viewProj)) return;
        groups.push_back(std::move(f));
    }
    std::vector<BoundingSphere> merged;
    while (groups.size() > 1) {
        size_t bi = 0, bj = 0;
        float bestSize = std::numeric_limits<float>::max();
        glm::mat4 bestViewProj{1.0f};
        for (size_t i = 0; i < groups.size(); ++i)
            for (size_t j = i + 1; j < groups.size(); ++j) {
                merged = groups[i].spheres;
                merged.insert(merged.end(), groups[j].spheres.begin(), groups[j].spheres.end());
                float size = 0.0f;
                glm::mat4 viewProj{1.0f};
                if (!fitFocus(l, merged, size, viewProj) || size >= bestSize) continue;
                bestSize = size;
                bestViewProj = viewProj;
                bi = i;
                bj = j;
            }
        if (bi == bj) break;  // no two groups fit one frustum
        const bool cheap = bestSize <= 1.25f * std::max(groups[bi].size, groups[bj].size);
        if (groups.size() <= size_t(kMaxFocusMaps) && !cheap) break;
        FocusGroup& a = groups[bi];
        a.draws.insert(a.draws.end(), groups[bj].draws.begin(), groups[bj].draws.end());
        a.spheres.insert(a.spheres.end(), groups[bj].spheres.begin(), groups[bj].spheres.end());
        a.size = bestSize;
        a.viewProj = bestViewProj;
        groups.erase(groups.begin() + std::ptrdiff_t(bj));
    }
    if (groups.empty() || groups.size() > size_t(kMaxFocusMaps)) return;
    // frustumSize: the spot's tan(half angle), a cube face's tan(45 degrees) = 1, the
    // directional box's half extent.
    for (const FocusGroup& f : groups)
        if (f.size > 0.5f * g.frustumSize) return;
    g.focusMaps = int(groups.size());
    g.unfocusedVirtual = unfocused.empty() ? 0 : 1;
    lp.unfocusedDraws = std::move(unfocused);
    for (size_t k = 0; k < groups.size(); ++k) {
        g.focusFrustumSize[int(k)] = groups[k].size;
        g.focusViewProj[k] = groups[k].viewProj;
        lp.focusDraws.push_back(groups[k].draws);
    }
}

// VPLs: needed when the virtual objects change the indirect light that can be seen; split over
// the lights with shadow maps (each gets a reflective shadow map).
void planVpls(const RendererOptions& o, bool anyCaster, bool anyReachesVirtual, bool virtualInView,
              bool surfacePointsHaveVirtual, FramePlan& plan) {
    if (o.vpl.count <= 0) {
        plan.vplReason = "VPL count is 0";
    } else if (!anyCaster) {
        plan.vplReason = "no light reaches any geometry";
    } else if (!o.graph.cullPasses) {
        plan.needVpls = true;
        plan.vplReason = "pass culling off";
    } else if (anyReachesVirtual) {
        plan.needVpls = true;
        plan.vplReason = "a light reaches a virtual object";
    } else if (virtualInView) {
        plan.needVpls = true;
        plan.vplReason = "a virtual object in view receives bounced light";
    } else {
        plan.vplReason = "no light reaches a virtual object and none is in view";
    }
    if (plan.needVpls) {
        int withRsm = 0;
        for (LightPlan& lp : plan.lights) withRsm += lp.castsShadow;
        int first = 0, k = 0;
        for (LightPlan& lp : plan.lights) {
            if (!lp.castsShadow) continue;
            lp.hasRsm = true;
            lp.firstVpl = first;
            lp.vplCount = ++k == withRsm ? o.vpl.count - first : o.vpl.count / withRsm;
            first += lp.vplCount;
        }
        plan.needRealOnlyIsm = surfacePointsHaveVirtual;
    }
}

}  // namespace

Renderer::Renderer(const Scene& scene, const CameraIntrinsics& camera, RendererOptions options)
    : options_(options) {
    options_.validate();
    // Without a mesh nothing is drawn: the frame graph would cull every pass and the composite
    // would be missing, which is the scene's problem, not the renderer's.
    if (scene.meshInstances().empty())
        throw FileError(scene.source.empty() ? "scene" : scene.source.string(),
                        "the scene has no mesh in its node tree: nothing to render or composite "
                        "(add the real surfaces' proxies and the virtual objects as meshes)");
    scene_ = std::make_unique<GpuScene>(scene, 16384, options_.environment.lights);
    scene_->setShadowPcf(options_.shadow.filter == ShadowFilter::Pcf);
    scene_->setShadowPixelFootprint(options_.shadow.pixelFootprint);
    projection_ = CameraProjection::make(camera);
    ctx_ = std::make_unique<FrameContext>(*scene_, projection_, options_);

    // The frame, in order (render/PassList.cpp).
    FrameGraph& g = graph_;
    const GLenum cameraFormat =
        options_.composite.cameraResponse.isSrgb() ? GL_SRGB8_ALPHA8 : GL_RGBA16F;
    g.importTexture(kCameraImage, cameraFormat, SizeRule::Camera, "camera frame");
    g.importTexture(kSceneEnvironmentMap, GL_RGBA16F, SizeRule::Scene, "scene environment");
    g.importTexture(kEnvironmentCamera, GL_SRGB8_ALPHA8, SizeRule::Scene,
                    "environment camera frame");
    const PassInit init{scene, *scene_, options_};
    for (const RegisteredPass& p : registeredPasses()) g.addPass(p.make(init));
    g.markOutput(kComposite);
    g.markOutput(kCompositeSrgb);
    g.compile();

    cameraImage_ = gl::Texture::create2D("camera image", camera.width, camera.height, cameraFormat);
    cameraImage_.setFilter(GL_NEAREST, GL_NEAREST);
    uploadCameraImage(cv::Mat());
    g.setImport(kCameraImage, cameraImage_);
    g.setImport(kSceneEnvironmentMap, scene_->environmentMap());
    planFrame(FrameInput{});
    for (const FrameGraph::Node& n : g.nodes()) n.pass->resize(*ctx_);
}

Renderer::~Renderer() = default;

void Renderer::uploadCameraImage(const cv::Mat& bgr) {
    const int w = projection_.camera.width, h = projection_.camera.height;
    cv::Mat rgba;
    if (bgr.empty()) {
        rgba = cv::Mat(h, w, CV_8UC4, cv::Scalar(0, 0, 0, 255));
    } else {
        if (bgr.cols != w || bgr.rows != h || bgr.type() != CV_8UC3)
            throw Error(
                fmt::format("camera image is {}x{} (type {}), but the calibration is for "
                            "{}x{} 8-bit BGR; use the calibration of this camera mode",
                            bgr.cols, bgr.rows, bgr.type(), w, h));
        cv::cvtColor(bgr, rgba, cv::COLOR_BGR2RGBA);
    }
    if (!rgba.isContinuous()) rgba = rgba.clone();
    const CameraResponse& response = options_.composite.cameraResponse;
    if (response.isSrgb()) {  // the sRGB texture decodes
        cameraImage_.upload(GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
        return;
    }
    // Linearised here with the camera's own response, into the half-float texture.
    cv::Mat linear(rgba.size(), CV_32FC4);
    for (int y = 0; y < rgba.rows; ++y) {
        const cv::Vec4b* in = rgba.ptr<cv::Vec4b>(y);
        cv::Vec4f* out = linear.ptr<cv::Vec4f>(y);
        for (int x = 0; x < rgba.cols; ++x)
            out[x] = {response.linear(0, in[x][0]), response.linear(1, in[x][1]),
                      response.linear(2, in[x][2]), 1.0f};
    }
    cameraImage_.upload(GL_RGBA, GL_FLOAT, linear.data);
}

// The frame's uniform blocks (GpuFrame, the lights) and its history rule.
void Renderer::writeFrameUniforms(const FrameInput& input, const glm::mat4& view,
                                  const glm::mat4& proj) {
    FrameContext& c = *ctx_;
    const GpuScene& s = *scene_;
    const glm::mat4 viewProj = proj * view;
    const glm::vec3 camPos(input.T_world_camera.translation);
    GpuFrame& f = c.frame;
    f.viewMatrix = view;
    f.projMatrix = proj;
    f.viewProj = viewProj;
    specularRectangles(s, view, viewProj, projection_, c);
    f.prevViewProj = prevViewProj_;
    f.cameraPos = glm::vec4(camPos, 1.0f);
    f.prevCameraPos = glm::vec4(prevCameraPos_, 1.0f);
    f.canvas =
        glm::vec4(projection_.canvasWidth, projection_.canvasHeight,
                  1.0f / float(projection_.canvasWidth), 1.0f / float(projection_.canvasHeight));
    f.lightCount = int(s.lights().size());
    f.vplCount = options_.vpl.count;
    f.interleave = options_.indirect.interleave;
    f.frameIndex = c.frameIndex;
    // A live environment is the real world's, captured by a camera.
    const int envFlag = c.environment.live                      ? kOriginReal
                        : !s.hasEnvironment()                   ? kOriginNone
                        : s.environmentOrigin() == Origin::Real ? kOriginReal
                                                                : kOriginVirtual;
    // Moved objects leave their history where they stood: start afresh (as after a cut).
    // Each pass that keeps a history adds its own part: it ran in the previous frame.
    c.historyValid = !input.resetHistory && !objectsMoved_ && c.frameIndex > 0;
    c.historyResetReason = c.frameIndex == 0    ? "first frame"
                           : input.resetHistory ? "cut, seek or tracking loss"
                           : objectsMoved_      ? "objects moved"
                                                : "";
    f.envOrigin = envFlag;
    f.historyValid = c.historyValid ? 1 : 0;
    f.ismTileSize = options_.ism.tileSize;
    f.ismTilesPerRow = ismTilesPerRow(options_.vpl.count);
    f.vplDistanceClamp = options_.indirect.distanceClamp;
    f.shadowBias = options_.shadow.bias;
    f.temporalBlend = options_.temporalBlend;
    f.ismPointsPerVpl = float(options_.ism.pointsPerVpl);
    // The exposure pass (when on) replaces it after measuring this frame; until then, and in
    // passes before it, the last frame's estimate (the prior before the first).
    if (!options_.exposureMatch.enabled) {
        c.exposure = ExposureState{};
        c.exposure.gain = glm::dvec3(double(options_.composite.exposure));
        c.exposure.note = "fixed exposure (matching off)";
    }
    f.exposure = glm::vec3(c.exposure.gain);
    f.alphaMax = options_.composite.alphaMax;
    f.alphaFadeLr = options_.composite.alphaFadeLr;
    c.frameUbo.upload(&f, sizeof(GpuFrame));
    c.lightUbo.upload(&c.lightBlock, sizeof(GpuLightBlock));
    if (c.frameIndex > 0)
        c.previous = FrameContext::PreviousCamera{prevViewProj_, prevTime_};
    else
        c.previous.reset();
    prevViewProj_ = viewProj;
    prevCameraPos_ = camPos;
    prevTime_ = input.time;
}

void Renderer::planFrame(const FrameInput& input) {
    FrameContext& c = *ctx_;
    const GpuScene& s = *scene_;
    FramePlan plan;
    const BoundingSphere& B = s.bounds();
    const float R = std::max(B.radius, 0.01f);

    // Camera.
    c.T_world_camera = input.T_world_camera;
    c.time = input.time;
    const glm::mat4 view(input.T_world_camera.inverse().matrix());
    const glm::mat4 proj = projection_.projectionMatrix(kNearM, kFarM);
    const glm::mat4 viewProj = proj * view;

    bool virtualInView = false;
    for (const DrawItem& d : s.draws())
        if (d.origin == Origin::Virtual && inFrustum(viewProj, d.bounds)) virtualInView = true;

    // Lights: matrices, caster tests, routing flags.
    c.lightBlock = GpuLightBlock{};
    int layer = 0;
    bool anyReachesVirtual = false, anyCaster = false;
    for (size_t i = 0; i < s.lights().size(); ++i) {
        const SceneLight& l = s.lights()[i];
        GpuLight& g = c.lightBlock.lights[i];
        LightPlan lp;
        bool real = false, virt = false, glassReal = false, glassVirtual = false,
             translucentInCone = false;
        for (const DrawItem& d : s.draws()) {
            if (!inLightCone(l, d.bounds)) continue;
            (d.origin == Origin::Real ? real : virt) = true;
            if (d.transmissive) (d.origin == Origin::Real ? glassReal : glassVirtual) = true;
            translucentInCone = translucentInCone || d.translucent;
        }
        lp.castsShadow = real || virt;
        lp.reachesVirtual = virt;
        lp.needsRealOnlyMap = lp.castsShadow && virt && real && l.origin == Origin::Real;
        planCaustics(l, s, options_.caustic.enabled, lp, plan);
        lp.glassTransmits = options_.shadow.glass && (glassReal || glassVirtual) && !lp.caustics;
        lp.translucentTransmits = options_.translucency.shadows && translucentInCone;
        lp.needsRealOnlyGlass = lp.needsRealOnlyMap && lp.hasGlassLayer();
        anyReachesVirtual = anyReachesVirtual || virt;
        anyCaster = anyCaster || lp.castsShadow;

        shadowMatrices(l, B, R, g, lp);
        if (!lp.castsShadow) lp.layers = 0;
        if (options_.shadow.focus && lp.needsRealOnlyMap) planVirtualFocus(l, s, lp, g);
        lp.firstLayer = layer;
        layer += lp.layers;
        g.firstShadowLayer = lp.firstLayer;
        g.shadowLayers = lp.layers;
        g.realOnlyMap = lp.needsRealOnlyMap ? 1 : 0;
        g.isReal = l.origin == Origin::Real ? 1 : 0;
        g.glassShadow = lp.hasGlassLayer() ? 1 : 0;
        plan.needRealOnlyShadows = plan.needRealOnlyShadows || lp.needsRealOnlyMap;
        plan.glassShadows = plan.glassShadows || lp.hasGlassLayer();
        plan.needRealOnlyGlass = plan.needRealOnlyGlass || lp.needsRealOnlyGlass;
        plan.lights.push_back(lp);
    }
    plan.shadowLayers = layer;
    for (size_t i = 0; i < plan.lights.size(); ++i) {  // focused maps after the light layers
        LightPlan& lp = plan.lights[i];
        lp.firstFocusLayer = plan.shadowLayers + plan.focusLayers;
        c.lightBlock.lights[i].firstFocusLayer = lp.firstFocusLayer;
        plan.focusLayers += int(lp.focusDraws.size());
    }
    if (plan.causticLayers > 0) {
        plan.causticReason = std::to_string(plan.causticLayers) +
                             " spot light(s) with a mirror or glass object in the cone";
    } else if (!options_.caustic.enabled) {
        plan.causticReason = "caustics off";
    } else {
        plan.causticReason = "no spot light's cone holds a mirror or glass object";
    }

    planVpls(options_, anyCaster, anyReachesVirtual, virtualInView, s.surfacePointsHaveVirtual(),
             plan);
    c.plan = plan;

    writeFrameUniforms(input, view, proj);
}

namespace {

// The inputs of the camera-independent passes besides the (static) scene and options: the light
// matrices and parameters, and the frame plan. Equal keys mean equal outputs.
std::string staticPlanKey(const FrameContext& c) {
    std::string key(reinterpret_cast<const char*>(&c.lightBlock), sizeof(GpuLightBlock));
    const FramePlan& p = c.plan;
    for (const LightPlan& l : p.lights)
        key += fmt::format("|{}{}{}{}{}{}{} {} {} {} {} u{}", int(l.castsShadow),
                           int(l.needsRealOnlyMap), int(l.reachesVirtual), int(l.hasRsm),
                           int(l.glassTransmits), int(l.translucentTransmits),
                           int(l.needsRealOnlyGlass), l.firstLayer, l.layers, l.firstVpl,
                           l.vplCount, fmt::join(l.unfocusedDraws, ","));
    for (const LightPlan& l : p.lights)  // which draws each focused map holds
        for (const std::vector<int>& draws : l.focusDraws)
            key += fmt::format("|f{}", fmt::join(draws, ","));
    for (const LightPlan& l : p.lights)
        key += fmt::format("|c{} {}", int(l.caustics), l.causticLayer) +
               std::string(reinterpret_cast<const char*>(&l.causticViewProj), sizeof(glm::mat4));
    key += fmt::format("|{} {} {}{}{}{}{}", p.shadowLayers, p.focusLayers, int(p.needVpls),
                       int(p.needRealOnlyShadows), int(p.needRealOnlyIsm), int(p.glassShadows),
                       int(p.needRealOnlyGlass));
    return key;
}

}  // namespace

const FrameReport& Renderer::render(const FrameInput& input) {
    if (!input.T_world_camera.isFinite())
        throw Error(
            "camera pose is not finite; pass resetHistory and skip the frame when "
            "tracking is lost");
    uploadCameraImage(input.cameraImage);
    if (envPosePending_) {
        // A mounted environment camera: its frame was taken with the main camera where this
        // frame's pose puts it.
        ctx_->environment.T_world_camera = envCamera_->poseInWorld(input.T_world_camera);
        envPosePending_ = false;
    }
    placeEnvironmentLights();
    planFrame(input);
    FrameContext& c = *ctx_;
    // What the camera-independent passes' output depends on: the light matrices and the plan.
    // Camera-independent passes (shadow maps, VPLs, ISMs, photons) are redone when objects moved.
    c.staticKey = staticPlanKey(c) + fmt::format("|g{}", scene_->generation());
    const FrameReport& report = graph_.execute(c, c.staticKey);
    objectsMoved_ = false;
    ++c.frameIndex;
    return report;
}

void Renderer::setQuality(const RendererOptions& quality) {
    RendererOptions next = options_;
    copyGovernedOptions(quality, next);
    next.validate();                      // throws before anything changed
    copyGovernedOptions(next, options_);  // ctx_ holds a reference to options_
}

bool Renderer::updateTransforms(const Scene& scene) {
    const GpuScene::TransformUpdate u = scene_->updateTransforms(scene);
    if (u.translucentMoved) return false;
    objectsMoved_ = objectsMoved_ || u.any();
    return true;
}

void Renderer::setEnvironmentCamera(const EnvironmentCameraSetup& camera) {
    if (!camera.intrinsics.isValid())
        throw Error("environment camera: invalid intrinsics (focal lengths and size must be > 0)");
    MR_CHECK(camera.T_world_camera.has_value() != camera.T_main_camera.has_value(),
             "environment camera: exactly one of T_world_camera and T_main_camera");
    envCamera_ = camera;
    const int w = camera.intrinsics.width, h = camera.intrinsics.height;
    if (envImage_.width() != w || envImage_.height() != h) {
        envImage_ = gl::Texture::create2D("environment camera frame", w, h, GL_SRGB8_ALPHA8);
        envImage_.setFilter(GL_LINEAR, GL_LINEAR);
        graph_.setImport(kEnvironmentCamera, envImage_);
    }
    EnvironmentInput& e = ctx_->environment;
    e.camera = camera.intrinsics;
    e.reachDeg = camera.reachDeg;
    e.gain = camera.gain;
    if (e.live) ++e.generation;  // a live map is rebuilt with the new camera
}

bool Renderer::updateEnvironment(const cv::Mat& bgr, double time) {
    if (!envCamera_)
        throw Error("updateEnvironment: no environment camera set (setEnvironmentCamera first)");
    const CameraIntrinsics& K = envCamera_->intrinsics;
    if (bgr.empty() || bgr.type() != CV_8UC3 || bgr.cols != K.width || bgr.rows != K.height)
        throw Error(
            fmt::format("environment camera frame is {}x{} (type {}), but its calibration "
                        "is for {}x{} 8-bit BGR; use the calibration of this camera mode",
                        bgr.cols, bgr.rows, bgr.type(), K.width, K.height));
    EnvironmentInput& e = ctx_->environment;
    if (e.live && time == e.time) return false;  // the same frame again: nothing new
    cv::Mat rgba;
    cv::cvtColor(bgr, rgba, cv::COLOR_BGR2RGBA);
    envImage_.upload(GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
    if (options_.environment.lights > 0) bgr.copyTo(envFrame_);
    e.live = true;
    e.time = time;
    ++e.generation;
    if (envCamera_->T_world_camera) {
        e.T_world_camera = *envCamera_->T_world_camera;
        envPosePending_ = false;
    } else {
        envPosePending_ = true;
    }
    return true;
}

// The lights of a new live environment frame (or none, for the static environment) become the
// scene's environment lights, and the diffuse environment light that of the map without them.
// Runs before the frame is planned, so that the frame's shadow maps are the new lights'.
void Renderer::placeEnvironmentLights() {
    EnvironmentInput& e = ctx_->environment;
    if (options_.environment.lights <= 0 || envLightsGeneration_ == e.generation) return;
    envLightsGeneration_ = e.generation;
    envLights_ = EnvironmentLightSplit{};
    e.lightFreeSHValid = false;
    std::vector<SceneLight> placed;
    if (e.live && !envFrame_.empty()) {
        LightEstimationOptions o;
        o.maxLights = options_.environment.lights;
        envLights_ = envLightFinder_.find(envFrame_, e.camera, e.reachDeg, e.T_world_camera, e.gain,
                                          options_.environment.lightMapWidth, o);
        for (size_t k = 0; k < envLights_.lights.size(); ++k) {
            const EstimatedLight& found = envLights_.lights[k];
            SceneLight l;
            l.name = "environment light " + std::to_string(k + 1);
            l.type = kLightDirectional;
            l.direction = -found.direction;  // it shines away from where it is
            l.radiantIntensity = found.irradiance;
            l.origin = Origin::Real;  // the room's light: it lights and shadows real and virtual
            placed.push_back(l);
        }
        if (!placed.empty()) {
            e.lightFreeSH = envLights_.lightFreeSH;
            e.lightFreeSeenFraction = envLights_.seenFraction;
            e.lightFreeSHValid = true;
        }
    }
    scene_->setEnvironmentLights(placed);
}

void Renderer::setEnvironmentGain(const glm::vec3& gain) {
    if (!std::isfinite(gain.r) || !std::isfinite(gain.g) || !std::isfinite(gain.b) || gain.r < 0 ||
        gain.g < 0 || gain.b < 0)
        throw Error("environment camera gain must be finite and >= 0 per channel");
    if (envCamera_) envCamera_->gain = gain;
    EnvironmentInput& e = ctx_->environment;
    e.gain = gain;
    if (e.live) ++e.generation;
}

void Renderer::useStaticEnvironment() {
    EnvironmentInput& e = ctx_->environment;
    if (!e.live) return;
    e.live = false;
    envPosePending_ = false;
    ++e.generation;
}

std::vector<std::string> Renderer::passNames() const {
    return graph_.passNames();
}

const gl::Texture& Renderer::compositeTexture() const {
    return graph_.texture(kCompositeSrgb);
}

cv::Mat Renderer::compositeLinear() const {
    const gl::Texture& t = graph_.texture(kComposite);
    auto px = t.read<float>(GL_RGBA, GL_FLOAT, 4);
    cv::Mat rgba(t.height(), t.width(), CV_32FC4, px.data()), rgb;
    cv::cvtColor(rgba, rgb, cv::COLOR_RGBA2RGB);
    return rgb;
}

cv::Mat Renderer::compositeSrgb() const {
    const gl::Texture& t = graph_.texture(kCompositeSrgb);
    auto px = t.read<unsigned char>(GL_RGBA, GL_UNSIGNED_BYTE, 4);
    cv::Mat rgba(t.height(), t.width(), CV_8UC4, px.data()), bgr;
    cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
    return bgr;
}

cv::Mat Renderer::compositeCameraCoded() const {
    const CameraResponse& response = options_.composite.cameraResponse;
    if (response.isSrgb()) return compositeSrgb();
    // From the linear composite: through 8-bit sRGB codes the darkest codes would merge.
    const cv::Mat linear = compositeLinear();
    cv::Mat bgr(linear.size(), CV_8UC3);
    for (int y = 0; y < linear.rows; ++y)
        for (int x = 0; x < linear.cols; ++x) {
            const cv::Vec3f& p = linear.at<cv::Vec3f>(y, x);
            cv::Vec3b& q = bgr.at<cv::Vec3b>(y, x);
            for (int k = 0; k < 3; ++k) q[2 - k] = uint8_t(response.code(k, p[k]));
        }
    return bgr;
}

cv::Mat Renderer::coverage() const {
    const gl::Texture& t = graph_.texture(kComposite);
    auto px = t.read<float>(GL_RGBA, GL_FLOAT, 4);
    cv::Mat out(t.height(), t.width(), CV_8U);
    for (int y = 0; y < t.height(); ++y)
        for (int x = 0; x < t.width(); ++x) {
            const float a = px[(size_t(y) * t.width() + x) * 4 + 3];
            out.at<uint8_t>(y, x) = a > 0.75f ? 2 : a > 0.25f ? 1 : 0;
        }
    return out;
}

cv::Mat Renderer::readIsmAtlas(bool realOnly) const {
    const Resource r = realOnly ? kImperfectShadowMapsReal : kImperfectShadowMaps;
    if (!graph_.has(r)) throw Error("no imperfect shadow map was rendered this frame");
    const gl::Texture& t = graph_.texture(r);
    auto bits = t.read<uint32_t>(GL_RED_INTEGER, GL_UNSIGNED_INT, 1);
    cv::Mat out(t.height(), t.width(), CV_32F);
    std::memcpy(out.data, bits.data(), bits.size() * 4);  // float bits were stored
    return out;
}

std::vector<GpuVpl> Renderer::readVpls() const {
    if (!graph_.has(kVpls)) throw Error("no VPLs were placed this frame");
    const gl::Buffer& b = graph_.buffer(kVpls);
    std::vector<GpuVpl> v(b.size() / sizeof(GpuVpl));
    glGetNamedBufferSubData(b.id(), 0, GLsizeiptr(v.size() * sizeof(GpuVpl)), v.data());
    return v;
}

cv::Mat Renderer::readEnvironmentMap() const {
    const gl::Texture& t = graph_.texture(kEnvironmentMap);
    auto px = t.read<float>(GL_RGBA, GL_FLOAT, 4);
    return cv::Mat(t.height(), t.width(), CV_32FC4, px.data()).clone();
}

GpuEnvironment Renderer::readEnvironmentLight() const {
    GpuEnvironment g{};
    glGetNamedBufferSubData(graph_.buffer(kEnvironmentLight).id(), 0, sizeof(g), &g);
    return g;
}

cv::Mat Renderer::readBuffer(Resource r) const {
    const gl::Texture& t = graph_.texture(r);   // throws if the frame did not produce it
    if (t.format() == GL_DEPTH_COMPONENT32F) {  // a depth buffer (SpecularMask): one channel
        auto depth = t.read<float>(GL_DEPTH_COMPONENT, GL_FLOAT, 1);
        return cv::Mat(t.height(), t.width(), CV_32FC1, depth.data()).clone();
    }
    auto px = t.read<float>(GL_RGBA, GL_FLOAT, 4);
    cv::Mat rgba(t.height(), t.width(), CV_32FC4, px.data()), rgb;
    cv::cvtColor(rgba, rgb, cv::COLOR_RGBA2RGB);
    return rgb;
}

}  // namespace mirage::render
