#include "core/scene/Scene.h"

#include <algorithm>

#include "core/Error.h"

namespace mirage {

namespace {

// Visits the nodes reachable from `roots` depth-first (parents before children, children in file
// order) without recursion, so a deep hierarchy cannot exhaust the stack. The loader guarantees
// the node graph is a forest, so every node is visited at most once.
template <class Visit>
void forEachReachableNode(const Scene& scene, Visit&& visit) {
    std::vector<int> stack(scene.roots.rbegin(), scene.roots.rend());
    while (!stack.empty()) {
        int index = stack.back();
        stack.pop_back();
        MR_CHECK(index >= 0 && index < static_cast<int>(scene.nodes.size()),
                 "node index out of range after loading");
        const Node& node = scene.nodes[static_cast<size_t>(index)];
        visit(index, node);
        for (auto it = node.children.rbegin(); it != node.children.rend(); ++it)
            stack.push_back(*it);
    }
}

}  // namespace

std::vector<MeshInstance> Scene::meshInstances() const {
    std::vector<MeshInstance> instances;
    forEachReachableNode(*this, [&](int index, const Node& node) {
        if (node.mesh >= 0) instances.push_back({index, node.mesh, node.world, node.origin});
    });
    return instances;
}

std::vector<LightInstance> Scene::lightInstances() const {
    std::vector<LightInstance> instances;
    forEachReachableNode(*this, [&](int index, const Node& node) {
        if (node.light < 0) return;
        LightInstance light;
        light.node = index;
        light.light = node.light;
        light.position = glm::dvec3(node.world[3]);
        // A light shines down its node's -Z axis (KHR_lights_punctual). The loader rejects light
        // nodes whose world matrix collapses -Z, so the normalisation is safe.
        light.direction = glm::normalize(glm::dmat3(node.world) * glm::dvec3(0.0, 0.0, -1.0));
        light.origin = node.origin;
        instances.push_back(light);
    });
    return instances;
}

int Scene::findCameraNode(const std::string& name) const {
    int found = -1;
    std::vector<std::string> available;
    forEachReachableNode(*this, [&](int index, const Node& node) {
        if (node.camera < 0) return;
        available.push_back("'" + node.name + "'");
        bool matches = name.empty() || node.name == name;  // lowest index wins
        if (matches && (found < 0 || index < found)) found = index;
    });
    if (found >= 0) return found;
    std::string list;
    for (const std::string& n : available) list += (list.empty() ? "" : ", ") + n;
    if (available.empty())
        throw Error(source.string() + ": the scene has no camera node" +
                    (name.empty() ? std::string() : " (looked for '" + name + "')") +
                    "; add a node with a perspective camera to the glTF file");
    throw Error(source.string() + ": no camera node named '" + name +
                "'; camera nodes in the scene: " + list);
}

const Material& Scene::material(int index) const {
    // glTF's default material: white, metallic 1, roughness 1 (glTF 2.0 spec, 3.9.6).
    static const Material kDefault = [] {
        Material m;
        m.name = "glTF default material";
        return m;
    }();
    if (index < 0) return kDefault;
    MR_CHECK(index < static_cast<int>(materials.size()), "material index out of range");
    return materials[static_cast<size_t>(index)];
}

bool Scene::hasVirtual() const {
    bool any = false;
    forEachReachableNode(*this, [&](int, const Node& node) {
        if ((node.mesh >= 0 || node.light >= 0) && node.origin == Origin::Virtual) any = true;
    });
    return any;
}

}  // namespace mirage
