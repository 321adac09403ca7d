#pragma once
// What a surface hands to a renderer or an exporter: a triangle mesh (lattice, vdb) or
// oriented discs (splat).

#include <variant>

#include "render/Mesh.h"
#include "render/Splats.h"

namespace rend::render {

using Geometry = std::variant<Mesh, Splats>;

}  // namespace rend::render
