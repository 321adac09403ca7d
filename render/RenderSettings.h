#pragma once
// What a renderer needs to know besides the frame: camera, lights, colouring, image size.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace rend::render {

/// Theta: the diffusive quantity, as a layer on the look (ThetaStyle::Layer) or light red ->
/// dark red as in the membrane paper's figures (ThetaStyle::PaperMap). Speed, Strain, Damage:
/// diagnostic maps that replace the look's colour.
enum class ColorBy { None, Speed, Strain, Theta, Damage };

/// What the sheet is made of, as a shading preset (render/Look.h): the material at theta = 0
/// and what the diffusing quantity does to it. Plain: the material, albedo, roughness and
/// transmission keys alone, theta as a red stain.
enum class Look { Plain, Foil, Film, Seaweed, Paper };

/// How color_by = "theta" shows: as the look's layer (heat tint, damp, etch, wet), or the
/// membrane paper's light-to-dark-red map replacing the material's colour.
enum class ThetaStyle { Layer, PaperMap };

/// Linear radiance to display: a filmic curve that rolls highlights off (render/ToneMap.h), or
/// a plain clamp at 1.
enum class ToneCurve { Filmic, Clamp };

struct ToneMapping {
    ToneCurve curve = ToneCurve::Filmic;
    double exposure = 0.0;  ///< stops: radiance is scaled by 2^exposure before the curve
};

struct Camera {
    Eigen::Vector3d position{0.0, -4.0, 3.0};
    Eigen::Vector3d lookAt{0.0, 0.0, 0.0};
    Eigen::Vector3d up{0.0, 0.0, 1.0};
    double fovYDegrees = 40.0;
};

struct DirectionalLight {
    Eigen::Vector3d direction{-0.4, -0.5, 1.0};  ///< points from the surface towards the light
    Eigen::Vector3d color{1.0, 1.0, 1.0};
    double intensity = 0.85;
};

/// Surface reconstruction of a frame (DESIGN.md, "Surfaces and rendering").
enum class SurfaceKind { Lattice, Splat, Vdb, ParticleLevelSet };

/// How the path tracer shades the membrane. Conductor: rough GGX metal (aluminium foil).
/// Film: translucent rough dielectric-like sheet (rubbery film). Translucent: thin diffuse with
/// transmission (seaweed, paper towel). Diffuse: plain Lambert.
enum class MaterialKind { Diffuse, Conductor, Film, Translucent };

struct PathTracing {
    int samplesPerPixel = 16;
    int maxDepth = 4;
    MaterialKind material = MaterialKind::Diffuse;
    double roughness = 0.35;    ///< GGX alpha = roughness^2
    double transmission = 0.0;  ///< fraction of light passing through (film, translucent)
    bool sky = true;            ///< sky gradient (zenith -> horizon); false: constant background
    Eigen::Vector3d skyZenith{0.35, 0.50, 0.80};
    Eigen::Vector3d skyHorizon{0.85, 0.88, 0.92};
    double sunAngularRadiusDegrees = 2.0;  ///< soft shadows
    /// Picks another set of random numbers (0: the default). A reference image rendered with
    /// another seed has noise independent of the images it judges (scripts/bench_cycles.sh).
    std::uint32_t seed = 0;
    /// Filter the frame's noise (render/Denoise.h), guided by each pixel's first hit: few
    /// samples then look like many. Off for measuring noise (scripts/bench_cycles.sh).
    bool denoise = false;
};

/// OpenVDB level set of the particles (ParticlesToLevelSet -> volumeToMesh).
struct VdbSettings {
    double voxelSize = 0.0;       ///< 0: dx / 2
    double particleRadius = 0.0;  ///< 0: 0.75 dx (>= 1.5 voxels, or OpenVDB skips particles)
    int smoothingIterations = 1;  ///< light mean-curvature smoothing; must not open holes
    double adaptivity = 0.1;      ///< volumeToMesh adaptivity in [0, 1]
};

/// How a collider (sim/Collider.h) is drawn: Lambert in `color`, or, when `metal`, a rough
/// conductor whose reflectance at normal incidence is `color`. The default is a neutral warm grey,
/// darker than the default sheet's albedo so a pale sheet stays visible against it.
struct ColliderLook {
    Eigen::Vector3d color{0.62, 0.60, 0.56};
    double roughness = 0.6;  ///< GGX alpha = roughness^2, as the sheet's
    bool metal = false;
};

struct RenderSettings {
    int width = 960;
    int height = 540;
    int supersample = 2;  ///< render at N x N the size and box-filter down
    Camera camera;
    DirectionalLight sun;
    double ambient = 0.25;
    Eigen::Vector3d background{0.80, 0.84, 0.90};
    bool ground = true;
    double groundHeight = -0.5;  ///< z of the ground plane
    Eigen::Vector3d groundColor{0.55, 0.55, 0.52};
    Eigen::Vector3d albedo{0.78, 0.80, 0.85};  ///< material colour at theta = 0
    Look look = Look::Plain;
    ThetaStyle thetaStyle = ThetaStyle::Layer;
    ToneMapping tone;
    ColorBy colorBy = ColorBy::None;
    std::optional<std::array<double, 2>> colorRange;  ///< nullopt: 0..max of the frame
    SurfaceKind surface = SurfaceKind::Lattice;
    double thickness = 0.0;  ///< lattice surface extruded to this thickness [m]; 0: a sheet
    PathTracing pathTracing;
    VdbSettings vdb;
    /// Index for index with FrameView::colliders; a collider past the end has the default look.
    std::vector<ColliderLook> colliderLooks;

    ColliderLook colliderLook(std::size_t collider) const {
        return collider < colliderLooks.size() ? colliderLooks[collider] : ColliderLook{};
    }
};

}  // namespace rend::render
