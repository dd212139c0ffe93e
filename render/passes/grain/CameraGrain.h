#pragma once
// The camera's noise and vignetting as the grain pass estimates them from the footage
// (docs/camera-matching.md), on the CPU so that the estimators can be tested without GL:
//  - the noise-level function: the variance of the footage's noise per channel as a function
//    of the linear value, from sample blocks where the rendered real surface L_r is smooth
//    (the footage minus the block's L_r scaled to it is the noise there), binned by intensity;
//    and the correlation of neighbouring pixels' noise;
//  - the vignetting: V(r) = 1 + k1 r^2 + k2 r^4, r = distance from the principal point over the
//    distance from it to the farthest image corner, fitted to footage / L_r of the sample blocks
//    of several frames, where the same surface point is seen at different image radii.
// Both are smoothed over frames by GrainEstimates (history weight, per frame).
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/camera/CameraModel.h"

namespace mirage::render {

// Intensity levels of the noise-level function, uniform in the sRGB-encoded value (0..1): finer
// in the dark, where the noise changes fastest with the value.
inline constexpr int kNoiseLevels = 8;

// One sample block of the footage (linear values, per channel R, G, B).
struct NoiseBlock {
    glm::vec3 mean{0.0f};      // the block's mean footage
    glm::vec3 variance{0.0f};  // of the footage around L_r scaled to the block (unbiased)
    float correlation = 0.0f;  // of horizontally neighbouring pixels' residuals (bias-corrected)
};

struct NoiseLevelFunction {
    // Noise variance (linear units squared) per channel at each level's centre value.
    std::array<glm::vec3, kNoiseLevels> variance{};
    float correlation = 0.0f;  // neighbouring pixels' noise correlation (0: white noise)
    int blocks = 0;            // blocks the estimate was made from
    // The linear value at the centre of level `i` (its sRGB-encoded value is (i + 0.5) / levels).
    static float levelValue(int i);
    // The variance at a linear value, per channel (linear interpolation between the levels,
    // constant beyond the first and last: the shader's rule, grain_apply.frag).
    glm::vec3 varianceAt(const glm::vec3& linear) const;
};

// The noise-level function of one frame: per channel and level the median of the blocks'
// variances (a level needs `minBlocksPerLevel` blocks); levels without enough blocks take the
// Poisson-Gaussian line (variance = a + b value, a, b >= 0) fitted to the measured ones.
// Nothing (and `why` says it) when no level has enough blocks.
std::optional<NoiseLevelFunction> estimateNoiseLevels(const std::vector<NoiseBlock>& blocks,
                                                      int minBlocksPerLevel, std::string& why);

struct VignetteSample {
    float r2 = 0.0f;        // squared normalised radius of the block's centre (0 centre, 1 corner)
    float ratio = 0.0f;     // footage / L_r luminance of the block
    glm::vec3 world{0.0f};  // the block's mean surface point (world, m): ties frames together
};

// Squared distance of camera pixel q (OpenCV pixel coordinates) from the principal point over
// that of the farthest image corner (pixel centres): 0 at the principal point, 1 in that corner.
float vignetteRadius2(const CameraIntrinsics& camera, glm::vec2 q);

struct VignetteProfile {
    float k1 = 0.0f, k2 = 0.0f;  // V(r) = 1 + k1 r^2 + k2 r^4
    float gain(float r2) const { return 1.0f + k1 * r2 + k2 * r2 * r2; }
};

// The vignetting from several frames' samples, free of the model's own error: footage / L_r of a
// block is c_f (the frame's exposure) x V(r) (the lens) x a_p (how wrong L_r is at the surface
// point p: albedo, the light's falloff, unmodelled light). Within one frame a_p varies with the
// image radius as much as V does (L_r's error towards the spot's edge looks like vignetting), so
// the fit takes only what changes when the same surface point (a world cell of `cellSize` m) is
// seen at another image radius in another frame: log ratio = log c_f + b1 r^2 + b2 r^4 + log a_p,
// least squares with a_p eliminated per cell (every quantity less its cell's mean) and one c_f per
// frame (the first fixed), then the samples beyond 3 robust deviations (at least 2 %) dropped and
// refitted, twice; V = exp(b1 r^2 + b2 r^4) ~ 1 + b1 r^2 + (b2 + b1^2 / 2) r^4. Nothing (and
// `why` says it) with fewer than `minSamples` samples in cells seen in two frames or more, a
// spread of those samples' r^2 about their cell's mean below `minSpread` (RMS: the camera has
// not moved enough), or a profile that is not a darkening of at most 80 % at the corner.
std::optional<VignetteProfile> fitVignetteAcrossFrames(
    const std::vector<std::vector<VignetteSample>>& frames, float cellSize, int minSamples,
    float minSpread, std::string& why);

// The estimates over frames: each frame's estimate blended in with weight 1 - history (the first
// one taken as it is); a frame without an estimate keeps the last. `note` says what was used.
class GrainEstimates {
public:
    void updateNoise(const std::optional<NoiseLevelFunction>& frame, float history,
                     const std::string& why);
    void updateVignette(const std::optional<VignetteProfile>& frame, float history,
                        const std::string& why);
    const std::optional<NoiseLevelFunction>& noise() const { return noise_; }
    const std::optional<VignetteProfile>& vignette() const { return vignette_; }
    // The last `keep` frames' vignetting samples (fitVignetteAcrossFrames' input): this frame's
    // added, the oldest dropped.
    const std::vector<std::vector<VignetteSample>>& vignetteSamples() const {
        return vignetteSamples_;
    }
    void addVignetteSamples(std::vector<VignetteSample> frame, size_t keep);
    int noiseFrames() const { return noiseFrames_; }
    int vignetteFrames() const { return vignetteFrames_; }
    std::string noiseNote, vignetteNote;

private:
    std::optional<NoiseLevelFunction> noise_;
    std::optional<VignetteProfile> vignette_;
    std::vector<std::vector<VignetteSample>> vignetteSamples_;
    int noiseFrames_ = 0, vignetteFrames_ = 0;
};

}  // namespace mirage::render
