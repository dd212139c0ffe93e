// The impostor tables' layout, written once: valid GLSL (included by trace.glsl) and valid C++
// (ImpostorTypes.h includes it in namespace mirage::render after render/GpuTypes.h, with vec3 =
// glm::vec3 etc., and checks the offsets). std430 storage buffers; every field named. World
// frame = glTF (metres, +Y up). trace.glsl reads the buffers as RGBA32F texels (impostorAt,
// impostorObjectAt) and the header as a uniform block: keep every struct a multiple of 16 bytes.
#ifndef MIRAGE_IMPOSTOR_TYPES_GLSL
#define MIRAGE_IMPOSTOR_TYPES_GLSL

const int kImpostorBillboard = 0;  // GpuImpostor::kind: a box on the far side of the object
const int kImpostorPlane = 1;      // a planar item (halfW = 0)

// One impostor of a surrounding draw item for one specular object (the records buffer). Its box
// is centre + [-1,1] * half extent along the three axes; axisW points away from the specular
// object (billboards) or is the plane normal (planes).
struct GpuImpostor {
    vec3 centre;    // world centre of the box
    int layer;      // layer in the impostor arrays (depth, normal, albedo, emissive)
    vec3 axisU;     // unit
    float halfU;    // half extent along axisU (m)
    vec3 axisV;     // unit
    float halfV;    // half extent along axisV (m)
    vec3 axisW;     // unit
    float halfW;    // half extent along axisW (m), 0 for planes
    int kind;       // kImpostorBillboard or kImpostorPlane
    int drawIndex;  // the item's index in GpuScene::draws()
    int pad0;       // std430: the struct is a multiple of 16 bytes
    int pad1;
};

// Per specular object (the objects buffer, kUnitImpostorObjects, after the GpuImpostorHeader).
struct GpuImpostorObject {
    vec3 centre;             // bounding-sphere centre (world, m) = the cube maps' centre
    float radius;            // bounding-sphere radius (m)
    int firstImpostor;       // its impostors: records[firstImpostor .. + impostorCount)
    int impostorCount;
    int baselineCubeLayer;   // first of the 6 layers of its plain cube map (baseline method)
    int enclosingCubeLayer;  // first of the 6 layers of its enclosing-items cube, -1 = none
    float enclosingReach;    // how far (m) the enclosing-items search marches along a ray
    float pad0;              // std430: the struct is a multiple of 16 bytes
    float pad1;
    float pad2;
};

// Head of the objects buffer (uniform block kBindingImpostorHeader).
struct GpuImpostorHeader {
    int cubeMapBaseline;       // 1: trace the plain cube-map baseline instead of impostors
    int refinementSteps;       // binary-search steps after the linear search
    int objectCount;           // specular objects (GpuImpostorObject entries)
    int coarseSamples;         // linear-search samples per impostor
    float cubeResolution;      // texels per side of a cube face
    float impostorResolution;  // texels per side of an impostor layer
    float pad0;                // std430: the struct is a multiple of 16 bytes
    float pad1;
};

#endif
