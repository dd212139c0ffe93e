// The frame, in order: one line per pass, naming its factory and its knobs (noKnobs when it has
// none). Adding a pass is its folder plus its line here (docs/realtime-renderer.md, "Adding a
// pass"). Passes know each other only through the resources they declare; the order is the
// order they run in, and the order `mirage bench` lists knobs that its column order
// (render/evaluation/BenchKnobs.cpp) does not place, and the governor's (render/governor).
#include <set>

#include <fmt/format.h>

#include "core/Error.h"
#include "render/PassRegistry.h"

#define MIRAGE_PASSES(X)                                                                  \
    X(makeEnvironmentPass, environmentKnobs)                                              \
    X(makeGBufferPass, noKnobs)                                                           \
    X(makeShadowPass, shadowKnobs)                                                        \
    X(makeImpostorPass, impostorKnobs)                                                    \
    X(makePhotonGBufferPass, noKnobs) /* before vpl: VPLs follow photons */               \
    X(makeVplPass, vplKnobs)                                                              \
    X(makeIsmPass, ismKnobs)                                                              \
    X(makeTranslucencyPass, translucencyKnobs)                                            \
    X(makeIndirectLightPass, indirectKnobs)                                               \
    X(makeGiFilterPass, noKnobs)                                                          \
    X(makeBackFacePass, noKnobs)        /* before direct: light through rough glass */    \
    X(makeDirectLightPass, directKnobs) /* + the upsampled indirect light */              \
    X(makeCausticPass, causticKnobs)                                                      \
    X(makeExposurePass, exposureKnobs) /* L_r complete; before any pass using exposure */ \
    X(makeSpecularGBufferPass, specularKnobs)                                             \
    X(makePhotonGridPass, noKnobs) /* caustics at the reflected/refracted hits */         \
    X(makeSpecularLightPass, noKnobs)                                                     \
    X(makeFuzzyReflectionPass, fuzzyKnobs)                                                \
    X(makeRoughRefractionPass, roughKnobs)                                                \
    X(makeCompositePass, compositeKnobs)                                                  \
    X(makeAntialiasPass, antialiasKnobs) /* the renderer's edges, after the composite */  \
    X(makeMotionBlurPass, noKnobs)       /* what the renderer added, over the exposure */ \
    X(makeGrainPass, grainKnobs)         /* the sensor adds its noise last */             \
    X(makeResourceViewPass, viewKnobs)   /* in place of the composite, when asked for */  \
    /* (the list's end: every pass's line ends in a backslash) */

namespace mirage::render {

#define MIRAGE_DECLARE_PASS(factory, knobs) std::unique_ptr<RenderPass> factory(const PassInit&);
MIRAGE_PASSES(MIRAGE_DECLARE_PASS)
#undef MIRAGE_DECLARE_PASS
#define MIRAGE_DECLARE_KNOBS(factory, knobs) std::vector<PassKnob> knobs();
MIRAGE_PASSES(MIRAGE_DECLARE_KNOBS)
#undef MIRAGE_DECLARE_KNOBS

// The knobs of a pass that has none of its own.
std::vector<PassKnob> noKnobs() {
    return {};
}

const std::vector<RegisteredPass>& registeredPasses() {
    static const std::vector<RegisteredPass> passes{
#define MIRAGE_REGISTER_PASS(factory, knobs) {#factory, &factory, &knobs},
        MIRAGE_PASSES(MIRAGE_REGISTER_PASS)
#undef MIRAGE_REGISTER_PASS
    };
    return passes;
}

const std::vector<PassKnob>& passKnobs() {
    static const std::vector<PassKnob> knobs = [] {
        std::vector<PassKnob> all;
        for (const RegisteredPass& p : registeredPasses())
            for (PassKnob& k : p.knobs()) all.push_back(std::move(k));
        std::set<std::string> names;
        for (const PassKnob& k : all)
            if (!names.insert(k.name).second)
                throw Error(fmt::format("two passes declare the knob '{}'", k.name));
        return all;
    }();
    return knobs;
}

}  // namespace mirage::render
