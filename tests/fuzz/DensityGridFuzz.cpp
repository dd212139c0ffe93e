// Fuzz target: the density grids of translucent materials (core/scene/DensityGrid.h): NRRD files
// through parseNrrdDensity, and anything else as raw float32 samples of a size taken from the
// input's length. Every accepted grid must hold only finite, non-negative samples and a majorant
// no smaller than any trilinear lookup, which the renderers' delta tracking relies on.
#include <cmath>
#include <cstdlib>
#include <string>

#include "core/Error.h"
#include "core/scene/DensityGrid.h"
#include "tests/fuzz/FuzzTarget.h"

namespace mirage::fuzz {
namespace {

void checkGrid(DensityGrid& g) {
    for (float v : g.values)
        if (!std::isfinite(v) || v < 0 || v > g.maxValue) std::abort();
    g.boundsMin = glm::vec3(-1.0f);
    g.boundsMax = glm::vec3(1.0f);
    for (int i = 0; i < 64; ++i) {
        glm::vec3 p(std::sin(float(i)), std::cos(float(i) * 1.7f), std::sin(float(i) * 0.3f));
        float d = g.density(p);
        if (!std::isfinite(d) || d < 0 || d > g.maxValue * 1.0001f) std::abort();
    }
}

bool run(const uint8_t* data, size_t size) {
    const std::string bytes(reinterpret_cast<const char*>(data), size);
    try {
        DensityGrid g;
        if (bytes.rfind("NRRD", 0) == 0) {
            g = parseNrrdDensity(bytes);
        } else {
            // Raw: as many float32 samples as fit, laid out as n x 1 x 1.
            int n = int(std::min<size_t>(size / 4, kMaxDensityDim));
            g = parseRawDensity(bytes.substr(0, size_t(n) * 4), n, 1, 1,
                                DensitySampleType::Float32);
        }
        checkGrid(g);
        return true;
    } catch (const Error&) {
        return false;
    }
}

}  // namespace

const Target& target() {
    static const Target t{"density_grid_fuzz",
                          {".nrrd", ".raw"},
                          {"NRRD0004\n",
                           "NRRD0001\n",
                           "type: float\n",
                           "type: double\n",
                           "type: uchar\n",
                           "type: ushort\n",
                           "dimension: 3\n",
                           "sizes: 2 2 2\n",
                           "sizes: 1024 1024 1024\n",
                           "sizes: 0 1 1\n",
                           "encoding: raw\n",
                           "encoding: gzip\n",
                           "endian: little\n",
                           "endian: big\n",
                           "data file: x\n",
                           "\n\n",
                           "\r\n\r\n",
                           "# comment\n",
                           "key:=value\n",
                           "nan",
                           "-1",
                           "1e39"},
                          run};
    return t;
}

}  // namespace mirage::fuzz
