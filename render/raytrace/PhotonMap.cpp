#include "render/raytrace/PhotonMap.h"

#include <cmath>

#include "core/Error.h"

namespace mirage::raytrace {

PhotonMap::PhotonMap(std::vector<Photon> photons, float radius) : radius_(radius) {
    MR_CHECK(radius > 0 && std::isfinite(radius), "photon gather radius must be positive");
    if (photons.empty()) return;
    uint32_t buckets = 1;
    while (buckets < 2 * photons.size()) buckets <<= 1;
    mask_ = buckets - 1;
    // Counting sort by bucket: deterministic order (stable in the input order).
    std::vector<uint32_t> bucketOf(photons.size());
    start_.assign(size_t(buckets) + 1, 0);
    for (size_t i = 0; i < photons.size(); ++i) {
        bucketOf[i] = bucket(cellOf(photons[i].position));
        ++start_[bucketOf[i] + 1];
    }
    for (uint32_t b = 0; b < buckets; ++b) start_[b + 1] += start_[b];
    std::vector<uint32_t> cursor(start_.begin(), start_.end() - 1);
    photons_.resize(photons.size());
    for (size_t i = 0; i < photons.size(); ++i) photons_[cursor[bucketOf[i]]++] = photons[i];
}

glm::ivec3 PhotonMap::cellOf(const glm::vec3& p) const {
    glm::vec3 c = glm::floor(p / radius_);
    // Far-away points clamp into a huge cell range rather than overflowing the int conversion.
    c = glm::clamp(c, glm::vec3(-1e8f), glm::vec3(1e8f));
    return glm::ivec3(c);
}

uint32_t PhotonMap::bucket(const glm::ivec3& c) const {
    uint32_t h = uint32_t(c.x) * 73856093u ^ uint32_t(c.y) * 19349663u ^ uint32_t(c.z) * 83492791u;
    return h & mask_;
}

}  // namespace mirage::raytrace
