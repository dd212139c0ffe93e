#pragma once
// The compositor: differential rendering of L_rv / L_r into the camera image, with the lens
// distortion applied through the remap table (docs/realtime-renderer.md).
#include "render/RenderPass.h"

namespace mirage::render {

// The output (camera image size): linear RGBA32F, a = coverage; the same, sRGB8.
inline constexpr Resource kComposite{"Composite"};
inline constexpr Resource kCompositeSrgb{"CompositeSrgb"};
// Camera size, RGBA16F: the footage part of each composite pixel and its layer (composite.frag's
// outFootage), for the motion blur; written only while RendererOptions::motionBlur is on.
inline constexpr Resource kCompositeFootage{"CompositeFootage"};

class CompositePass final : public RenderPass {
public:
    CompositePass() = default;  // the programs are built by resize(), for the camera
    // True when every camera pixel sees the canvas pixel of its own coordinates: no lens
    // distortion and a canvas of the camera's size (the composite's identity-remap variant).
    static bool isIdentityRemap(const CameraProjection& p);
    const char* name() const override { return "composite"; }
    void setup(PassBuilder& b) const override;
    PassDecision decide(const FrameContext& ctx) const override;
    void resize(const FrameContext& ctx) override;
    void execute(FrameContext& ctx, PassResources& res) override;

private:
    // The camera pixels (GL window rect) whose canvas position lies in canvasRect (canvas GL
    // window rect): where the composite can meet a specular pixel. Empty for an empty rect.
    glm::ivec4 cameraRect(const FrameContext& ctx, const glm::ivec4& canvasRect) const;
    // The variants below, with MIRAGE_IDENTITY_REMAP when `identityRemap`.
    // translucentReflection: also the variant that composites a translucent object's pixels with
    // its boundary's reflection (programTranslucent_), built only for scenes with one.
    // The specular variants the scene can use (`prepareFirstExitOnly`: also the one a governor
    // may switch to) are built here.
    void buildPrograms(const FrameContext& ctx, bool identityRemap, bool translucentReflection);

    // The variants: llvmpipe runs both sides of every branch (SIMD masks), so the specular
    // compositing code would cost every frame even behind a uniform that turns it off. With
    // Eqs. 6-11 for mirror / glass pixels, one per SpecularKind: the whole code, the same without
    // the glass's second exit, and the mirrors' alone (no refraction) for the rectangles without
    // glass. Built with the others for what the scene holds, else on first use.
    enum SpecularKind { kGlass, kGlassFirstExitOnly, kReflectionOnly, kSpecularKinds };
    struct SpecularVariant {
        gl::Program program;
        GLint epsilon = -1, showVirtual = -1, withCaustics = -1, secondExit = -1, fuzzyOn = -1,
              denoiseFootage = -1, noiseVariance = -1;  // footage_noise.glsl
    };
    const SpecularVariant& specularVariant(SpecularKind kind);
    void drawSpecular(FrameContext& ctx, const PassResources& res,
                      const std::vector<glm::ivec4>& glassRects,
                      const std::vector<glm::ivec4>& mirrorRects, int withCaustics);
    SpecularVariant specular_[kSpecularKinds];
    std::string identityDefine_;            // of the variants built
    gl::Program programDiffuse_;            // MIRAGE_DIFFUSE_ONLY: frames without specular objects
    gl::Program programDiffuseNoCaustics_;  // and MIRAGE_NO_CAUSTICS: no caustic pass this frame
    // MIRAGE_DIFFUSE_ONLY + MIRAGE_TRANSLUCENT_REFLECTION: over the translucent objects'
    // rectangles, the translucent pixels again with their boundary's reflection (the others
    // discarded). Apart so that no other pixel pays for the reflection's code on llvmpipe.
    gl::Program programTranslucent_;
    GLint locShowVirtualTranslucent_ = -1, locWithCausticsTranslucent_ = -1;
    bool programsBuilt_ = false, identityRemap_ = false;  // the variants built, and which
    bool translucentReflection_ = false;
    bool remapIsIdentity_ = false;  // isIdentityRemap of the camera the tables were built for
    gl::Texture linear_, srgb_, remap_, footage_;
    // Canvas size, RG32F: the camera-image pixel (OpenCV convention) that sees each canvas
    // pixel's ray (CameraIntrinsics::project), -1e4 where none does: CI(x) of Eq. 8-10.
    gl::Texture canvasToCamera_;
    std::vector<glm::vec2> canvasToCameraTable_;  // its CPU copy, row-major canvas pixels
    GLint locShowVirtualDiffuse_ = -1;            // of programDiffuse_
    GLint locWithCausticsDiffuse_ = -1, locShowVirtualNoCaustics_ = -1;
    gl::Framebuffer fbo_;
    // composite_mask.frag: depth 0 on the camera pixels that see a mirror or glass pixel, 1
    // elsewhere; fbo_'s depth attachment, so the full variant shades only those pixels.
    gl::Program maskProgram_;
    gl::Texture mask_;
    gl::Framebuffer maskFbo_;
    DrawnRects maskDrawn_;
};

}  // namespace mirage::render
