#pragma once
// [contact] and [[collider]] of a scene file (app/ContactLoader.cpp).

#include "app/Scene.h"
#include "app/SceneReader.h"

namespace rend {

/// Reads the ground, self-contact and colliders into scene.sim.contact and the colliders' looks
/// into scene.render; call after [render], whose ground it follows.
void readContact(const scene::TableReader& root, Scene& scene);

}  // namespace rend
