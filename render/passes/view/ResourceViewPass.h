#pragma once
// The resource view: any texture of the frame (a G-buffer, a light buffer, the motion velocity,
// a shadow atlas's first layer) shown in place of the composite, stretched over the camera
// image and scaled (ViewOptions), so a user can see what a pass made of their footage and
// scene (`mirage replay --set view=GBufferNormal`). The last pass of the frame: it writes new
// versions of Composite and CompositeSrgb, so every output (the window, a recording, the
// readbacks) shows the view. Off by default; it then never runs.
#include <string>

#include "render/RenderPass.h"
#include "render/passes/composite/CompositeVersion.h"
#include "render/passes/view/ViewOptions.h"

namespace mirage::render {

class ResourceViewPass final : public RenderPass {
public:
    // Throws mirage::Error when the options are out of range.
    explicit ResourceViewPass(const ViewOptions& options);
    const char* name() const override { return "view"; }
    // Throws mirage::Error (naming the knob) when the resource is the composite itself or no
    // import or earlier pass declares it.
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    // Throws mirage::Error when the resource is a buffer, an integer texture, or neither a 2D
    // texture nor a 2D array.
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    ViewOptions options_;
    std::string resourceName_;  // the storage of the Resource the graph keeps (its name pointer)
    gl::Program flatProgram_, arrayProgram_;
    gl::Sampler nearest_;
    CompositeVersion output_{"view"};
};

}  // namespace mirage::render
