#pragma once
// [[material.map]] of a scene file (app/MaterialMapLoader.cpp): sim/MaterialMap.h's factor
// fields, with their images read here (sim/ reads no files).

#include "app/Scene.h"
#include "app/SceneReader.h"

namespace rend {

/// Reads every [[material.map]] into scene.sim.materialMaps; call after [sheet] and
/// [material] and the solver, which it checks the maps against.
void readMaterialMaps(const scene::TableReader& root, Scene& scene);

}  // namespace rend
