#pragma once
// The kinematic colliders of a frame (sim/Collider.h) as world-space triangle meshes, for the
// renderers to draw: spheres and capsules smooth-shaded, boxes with flat faces, mesh colliders
// with angle-weighted vertex normals. Every mesh is counter-clockwise seen from outside.

#include <vector>

#include "render/Mesh.h"
#include "sim/Collider.h"
#include "sim/FrameView.h"

namespace rend::render {

/// Sectors around a sphere's or capsule's axis, and rings from pole to pole of a sphere (a
/// capsule's hemisphere has half as many): 5.6 degrees apart, so a sphere that fills the height of
/// a 1280x720 frame (r = 360 px) strays at most r (1 - cos 2.8 deg) < 0.5 px from its outline.
inline constexpr int kColliderSegments = 64;
inline constexpr int kColliderRings = 32;

/// One collider's triangles at `pose`, with unit per-vertex normals and no colours (the
/// renderers take the colour from RenderSettings::colliderLooks). Throws std::invalid_argument
/// for a mesh collider without a mesh, or with an index out of range.
Mesh colliderMesh(const sim::ColliderParams& collider, const sim::ColliderPose& pose);

/// Every collider of `frame` at its pose, index for index with frame.colliders. Throws
/// std::invalid_argument when the frame's colliders and poses differ in number.
std::vector<Mesh> colliderMeshes(const sim::FrameView& frame);

}  // namespace rend::render
