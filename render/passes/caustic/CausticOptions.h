#pragma once
// Options of the caustics (render/passes/caustic, docs/caustics.md).
#include "render/PassOptions.h"

namespace mirage::render {

struct CausticOptions {
    // Caustics from spot lights (Knecht 2013 Sec. 4.2, 5.2): photon G-buffers of mapSize^2 texels
    // per spot light whose cone holds a mirror or glass object (the frustum fitted to the
    // objects' bounding sphere), splatted as quads whose world radius is quadScale x the spacing
    // of neighbouring photons on the receiver (Wyman 2008).
    bool enabled = true;
    int mapSize = 256;
    float quadScale = 1.5f;
    // Caustics seen in reflections and refractions: the photons sorted into a world-space hashed
    // grid (PhotonGridPass) and gathered at every reflected / refracted hit by the specular light
    // pass, with each photon's kernel radius (quadScale photon spacings, widened to 1.5 of the
    // hit's pixel footprints) at most gatherRadius metres, or up to twice that where the pixels
    // are coarser (the grid's cells are twice it: the gather's cost grows with it). false: those
    // hits get no caustic.
    bool gather = true;
    float gatherRadius = 0.01f;
    // Photons the gather reads per grid bucket (0: all). A focused caustic puts tens of thousands
    // of photons into one cell, and every hit near it would read them all (a glass sphere alone
    // under a spot: the specular light pass 20x slower). Above the cap, a bucket is read by its
    // finest stratified subsample of the photon map (every 2nd, 4th, 8th or 16th texel per axis:
    // the grid stores each bucket's photons by that level) of at most cap photons, weighted by
    // count / read and with kernels widened by the stride, so the estimate keeps its expectation.
    // The photons read depend on their texels only, not on the order the grid's scatter stored
    // them in (atomics on a multithreaded rasteriser vary it from run to run), so a capped frame
    // is reproducible; hence on by default (docs/caustics.md, "The gather's cap").
    int gatherCap = 64;
    // Temporal smoothing of the caustic buffer (Knecht 2013 end of Sec. 4.2; caustic_resolve.frag):
    // this frame's caustic irradiance blended with last frame's, reprojected by the receiver's
    // world position and rejected where the surface there is at another distance, with the GI
    // filter's reset rules (render/TemporalHistory.h). A tracked camera jitters every frame,
    // which moves the photon footprints over the pixels: without it the caustic shimmers. false:
    // every frame's caustic stands alone.
    bool temporal = true;
    // Photons leaving a rough mirror, rough metal or rough glass (roughness above 0.05) each take
    // a microfacet normal sampled from the surface's GGX lobe (photon_gbuffer.frag), so the
    // caustic and the reflected / refracted VPLs spread as the reference's microfacet BSDF
    // spreads them (a rough mirror throws a soft glow, not its smooth twin's sharp patch;
    // docs/caustics.md, "Rough surfaces"). false: every photon follows the mirror / Snell ray.
    bool roughLobes = true;
    // Temporal reuse of the caustic buffer (docs/caustics.md, "Refreshing every N frames"): the
    // photons are splatted in one frame of every refreshInterval; in the frames between, the
    // caustic irradiance is last frame's, reprojected by the receiver's world position (a caustic
    // lies on diffuse receivers: it does not depend on the view) with the smoothing's same-surface
    // test. A receiver whose history is rejected (disoccluded) has no caustic until the next
    // refresh; a frame that drops the history (first frame, cut, objects moved) splats. 1: every
    // frame.
    int refreshInterval = 1;
    // A frame reuses the history only while at most this share of its view is new against last
    // frame's (CausticTiles.h newViewShare, at the caustic receivers' distances): a caustic that
    // comes into view is splatted at once instead of missing until the next refresh. The live
    // loop renders one camera frame in several, between which a hand-held camera turns by tens
    // of degrees. 1: reuse whatever the motion.
    float reuseMaxNewView = 0.02f;
    // Tests only: true resolves every canvas pixel, instead of only those in the 8x8 tiles the
    // photons reached this frame or where last frame's history can pass (CausticTiles.h; the
    // same images: every other pixel's caustic is 0).
    bool resolveEverywhere = false;
    // Tests only: true leaves the history's tiles out of that choice (a caustic kept by the
    // history alone, in a frame that reuses it, is lost).
    bool tilesIgnoreHistory = false;

    void validate() const {
        checkOption(mapSize >= 16 && mapSize <= 2048 && mapSize % 8 == 0, "caustic.mapSize",
                    "a multiple of 8 in 16..2048 texels", mapSize);
        checkOption(quadScale >= 0.25f && quadScale <= 8.0f, "caustic.quadScale",
                    "in [0.25, 8] (photon spacings)", quadScale);
        checkOption(gatherRadius >= 0.001f && gatherRadius <= 0.5f, "caustic.gatherRadius",
                    "in [0.001, 0.5] (metres)", gatherRadius);
        checkOption(gatherCap >= 0 && gatherCap <= (1 << 20), "caustic.gatherCap",
                    "0 (all photons) or 1..1048576 photons per bucket", gatherCap);
        checkOption(refreshInterval >= 1 && refreshInterval <= 8, "caustic.refreshInterval",
                    "1..8 frames", refreshInterval);
        checkOption(reuseMaxNewView >= 0.0f && reuseMaxNewView <= 1.0f, "caustic.reuseMaxNewView",
                    "a share of the view in [0, 1]", reuseMaxNewView);
    }
};

}  // namespace mirage::render
