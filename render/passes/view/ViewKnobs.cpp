// The resource view's knob (render/PassKnob.h): `view=NAME` or `view=NAME*SCALE` (a resource of
// the frame, its texels multiplied by SCALE), `view=off`.
#include <algorithm>
#include <cctype>
#include <cstdint>

#include <fmt/format.h>

#include "core/Error.h"
#include "render/PassKnob.h"
#include "render/passes/view/ViewOptions.h"

namespace mirage::render {

std::vector<PassKnob> viewKnobs() {
    return {PassKnob{
        "view",
        "show a frame resource in place of the composite: off, NAME or NAME*SCALE (e.g. "
        "GBufferNormal, LRv*4; docs/realtime-renderer.md lists the resources)",
        {},
        {},
        [](RendererOptions& o, const std::string& v) {
            ViewOptions view;
            if (v != "off") {
                const size_t star = v.find('*');
                view.resource = v.substr(0, star);
                // Every resource is named in CamelCase from a capital (GBufferNormal, LRv); which
                // exist is the frame graph's to say when the renderer is built.
                const bool camelCase = !view.resource.empty() &&
                                       std::isupper(uint8_t(view.resource[0])) &&
                                       std::all_of(view.resource.begin(), view.resource.end(),
                                                   [](char c) { return std::isalnum(uint8_t(c)); });
                if (!camelCase)
                    throw Error(
                        fmt::format("knob 'view': '{}' is not off, NAME or NAME*SCALE (a "
                                    "resource's name, e.g. GBufferNormal or LRv*4)",
                                    v));
                if (star != std::string::npos)
                    view.scale = float(
                        parseKnobNumber("view", v.substr(star + 1), 0.0, 1e6, true, "a scale"));
            }
            o.passes.get<ViewOptions>() = view;
        },
        [](const RendererOptions& o) {
            const ViewOptions& view = o.passes.get<ViewOptions>();
            if (view.resource.empty()) return std::string("off");
            return view.scale == 1.0f ? view.resource
                                      : fmt::format("{}*{}", view.resource, view.scale);
        }}};
}

}  // namespace mirage::render
