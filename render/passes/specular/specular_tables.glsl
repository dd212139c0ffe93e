#ifndef MIRAGE_SPECULAR_TABLES_GLSL
#define MIRAGE_SPECULAR_TABLES_GLSL
// The scene's material table and specular draw table (GpuScene::materialBuffer and
// specularDrawBuffer, bound by the pass) for the helpers that follow a specular pixel's path by
// its draw slot (second_exit.glsl, passes/direct/rough_transmission.glsl).
layout(std430, binding = kBindingMaterials) readonly buffer SpecularMaterialTable {
    GpuMaterial specularMaterialTable[];
};
layout(std430, binding = kBindingSpecularDraws) readonly buffer SpecularDrawTable {
    GpuSpecularDraw specularDrawTable[];
};

#endif
