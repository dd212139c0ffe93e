#pragma once
// Caustic photons of one pass and a hashed uniform grid to find those within a radius.
// Cell size = query radius, so a query visits the 3x3x3 cells around the point; hashed cells that
// collide are visited once (a photon is never counted twice).
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace mirage::raytrace {

struct Photon {
    glm::vec3 position{0.0f};  // world, on the surface where it landed
    glm::vec3 wi{0.0f};        // unit, pointing back where the photon came from
    glm::vec3 normal{0.0f};    // geometric normal at the landing point (facing the photon)
    glm::vec3 power{0.0f};     // flux, W per colour channel, already divided by the photons emitted
};

class PhotonMap {
public:
    PhotonMap() = default;
    PhotonMap(std::vector<Photon> photons, float radius);

    bool empty() const { return photons_.empty(); }
    size_t size() const { return photons_.size(); }
    float radius() const { return radius_; }

    // Calls fn(const Photon&) for every photon within `radius()` of p.
    template <typename Fn>
    void forEachNear(const glm::vec3& p, Fn&& fn) const {
        if (photons_.empty()) return;
        glm::ivec3 c = cellOf(p);
        uint32_t visited[27];
        int nVisited = 0;
        float r2 = radius_ * radius_;
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    uint32_t b = bucket(c + glm::ivec3(dx, dy, dz));
                    bool seen = false;
                    for (int i = 0; i < nVisited; ++i) seen |= visited[i] == b;
                    if (seen) continue;
                    visited[nVisited++] = b;
                    for (uint32_t i = start_[b]; i < start_[b + 1]; ++i) {
                        const Photon& ph = photons_[i];
                        glm::vec3 d = ph.position - p;
                        if (glm::dot(d, d) <= r2) fn(ph);
                    }
                }
    }

private:
    glm::ivec3 cellOf(const glm::vec3& p) const;
    uint32_t bucket(const glm::ivec3& c) const;

    std::vector<Photon> photons_;  // sorted by bucket
    std::vector<uint32_t> start_;  // bucket b holds photons_[start_[b], start_[b+1])
    float radius_ = 0.0f;
    uint32_t mask_ = 0;
};

}  // namespace mirage::raytrace
