#pragma once
/// \file Flat subdivision of triangle meshes (a scene file's "subdivide").

#include <vector>

#include "amalgam/scene/scene.h"
#include "amalgam/scene/texture.h"
#include "amalgam/scene/vertex_normals.h"

namespace amalgam {

/// Splits every triangle into 4 at its edge midpoints, `levels` times: the same surface with
/// 4^levels times the triangles, each keeping its material. `triangles` must all be
/// kTriangle; levels <= 0 returns them unchanged.
std::vector<Primitive> subdivide(const std::vector<Primitive>& triangles, int levels);

/// The texture coordinates of the triangles `subdivide` makes, in the same order.
std::vector<TexCoords> subdivide(const std::vector<TexCoords>& uvs, int levels);

/// The vertex normals of the triangles `subdivide` makes, in the same order: at a midpoint the
/// mean of the edge's two normals, unnormalised, so that interpolating across a finer triangle
/// gives exactly what interpolating across the coarse one gave (the surface stays flat).
std::vector<VertexNormals> subdivide(const std::vector<VertexNormals>& normals, int levels);

}  // namespace amalgam
