#pragma once
// The reconstruction's fused geometry as an in-memory scene of real meshes (the table top as a
// quad on its plane, each object's mesh), so that GeometryEvaluation can score it against the
// true scene without writing glTF.
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "core/scene/Scene.h"
#include "render/reconstruction/ProxyGeometry.h"

namespace mirage::test {

// Every object of `g` but the one named `leaveOut` (none when empty).
inline Scene fusedGeometryScene(const reconstruction::FusedGeometry& g,
                                const std::string& leaveOut = "") {
    Scene s;
    auto add = [&](const std::string& name, std::vector<glm::vec3> pos, std::vector<uint32_t> idx) {
        Mesh m;
        m.name = name;
        Primitive p;
        p.positions = std::move(pos);
        p.indices = std::move(idx);
        m.primitives.push_back(std::move(p));
        s.meshes.push_back(std::move(m));
        Node n;
        n.name = name;
        n.mesh = int(s.meshes.size()) - 1;
        n.origin = Origin::Real;
        s.nodes.push_back(n);
        s.roots.push_back(int(s.nodes.size()) - 1);
    };
    const reconstruction::TableEstimate& t = g.table;
    auto at = [&](double u, double v) { return glm::vec3(t.plane.toWorld({u, v, 0})); };
    add("table", {at(t.uMin, t.vMin), at(t.uMax, t.vMin), at(t.uMax, t.vMax), at(t.uMin, t.vMax)},
        {0, 1, 2, 0, 2, 3});
    for (const auto& o : g.objects)
        if (o.name != leaveOut) add(o.name, o.positions, o.indices);
    return s;
}

}  // namespace mirage::test
