// The view pass's texture units (valid GLSL and C++, like render/bindings.glsl; a unit's number
// only has to be unique among what one program samples, so the pass names its own here).
#ifndef MIRAGE_VIEW_UNITS_GLSL
#define MIRAGE_VIEW_UNITS_GLSL
const int kUnitViewSource = 0;  // the resource shown: a 2D texture, or a 2D array's layer
#endif
