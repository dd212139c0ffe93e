// Temporal history, per texel (after common.glsl): the reprojection of a world point with last
// frame's camera and the test that a history texel is the same surface, shared by every pass
// that smooths over frames (gifilter, caustic, speclight; render/TemporalHistory.h holds the per-frame
// rule). A history texel stores, beside its value, the camera distance (m) of the surface it was
// computed for.

// Where world point p was in last frame's canvas (uv in [0, 1], GL row 0 = image row 0, as
// every canvas buffer); false when it was behind that camera or outside its canvas.
bool reprojectToPreviousFrame(vec3 p, out vec2 prevUv) {
    vec4 prev = prevViewProj * vec4(p, 1.0);
    prevUv = vec2(-1.0);
    if (!(prev.w > 1e-6)) return false;
    prevUv = prev.xy / prev.w * 0.5 + 0.5;
    return all(greaterThanEqual(prevUv, vec2(0.0))) && all(lessThanEqual(prevUv, vec2(1.0)));
}

// The history texel (its stored camera distance, m) belongs to p's surface: last frame's camera
// saw a surface at p's distance from it, within 2 % + 5 mm (a disocclusion, an edge blended by
// the bilinear lookup or an empty texel, distance 0, fails).
bool historyIsSameSurface(float storedCameraDistance, vec3 p) {
    float expected = length(p - prevCameraPos.xyz);
    return abs(storedCameraDistance - expected) < 0.02 * expected + 0.005;
}
