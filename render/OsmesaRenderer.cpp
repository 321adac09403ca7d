#include "render/OsmesaRenderer.h"

#include <GL/osmesa.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>
#include <stdexcept>
#include <vector>

#include "render/GlMath.h"
#include "render/Look.h"
#include "render/ToneMap.h"

namespace rend::render {

namespace {

// Output encoding: GL shades in linear space into a float buffer, and the box-filtered result
// is tone mapped and gamma encoded (ToneMap.h). Filtering before encoding keeps edges from
// darkening, and the float buffer avoids banding in the shadows that an 8-bit linear buffer
// would cause. Fixed-function GL clamps every lit colour to 1, so all light is drawn at
// 1 / kHeadroom and scaled back before the tone curve: highlights up to kHeadroom survive.
constexpr double kHeadroom = 4.0;
// Fixed-function GL has no environment for a metal to reflect; a fraction of its reflectance
// as diffuse colour stands in for the sky and ground it would mirror.
constexpr float kMetalDiffuse = 0.35f;
// Fresnel reflectance at normal incidence of a dielectric with IOR 1.5, as in the path tracer.
constexpr float kDielectricF0 = 0.04f;
// GL's largest specular exponent.
constexpr float kMaxShininess = 128.0f;

// The ground quad reaches far past anything the camera frames, and fog toward the background
// colour dissolves its edge into a horizon instead of a visible border.
constexpr double kGroundExtent = 50.0;
constexpr double kFogStart = 3.0;
constexpr double kFogEnd = 30.0;
// Fixed-function fog is evaluated and clamped per vertex, so one giant quad would be fogged
// uniformly by its far corners; a grid keeps the fade tied to the actual distance.
constexpr int kGroundCells = 64;

void setColor(GLenum pname, const Eigen::Vector3d& rgb) {
    const GLfloat v[4] = {float(rgb.x()), float(rgb.y()), float(rgb.z()), 1.0f};
    glLightfv(GL_LIGHT0, pname, v);
}

double cameraDistance(const Camera& camera) {
    return std::max((camera.position - camera.lookAt).norm(), 1e-6);
}

void loadCamera(const RenderSettings& s, int width, int height) {
    const double dist = cameraDistance(s.camera);
    // The far plane must hold the whole ground quad; near at 1% keeps 24-bit depth adequate.
    const double zNear = 0.01 * dist;
    const double zFar = 2.0 * kGroundExtent * dist;
    const auto proj =
        detail::perspective(s.camera.fovYDegrees, double(width) / height, zNear, zFar);
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixd(proj.data());
    const auto view = detail::lookAt(s.camera.position, s.camera.lookAt, s.camera.up);
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixd(view.data());
}

void setupLighting(const RenderSettings& s) {
    glEnable(GL_LIGHTING);
    glEnable(GL_LIGHT0);
    glEnable(GL_NORMALIZE);
    glLightModeli(GL_LIGHT_MODEL_TWO_SIDE, GL_TRUE);
    glLightModeli(GL_LIGHT_MODEL_LOCAL_VIEWER, GL_TRUE);  // highlights where the camera sees them
    const float a = float(s.ambient / kHeadroom);
    const GLfloat ambient[4] = {a, a, a, 1.0f};
    glLightModelfv(GL_LIGHT_MODEL_AMBIENT, ambient);
    // Issued after the view matrix is loaded, so the direction is taken in world space.
    const Eigen::Vector3d d = s.sun.direction.normalized();
    const GLfloat position[4] = {float(d.x()), float(d.y()), float(d.z()), 0.0f};
    glLightfv(GL_LIGHT0, GL_POSITION, position);
    setColor(GL_DIFFUSE, s.sun.color * s.sun.intensity / kHeadroom);
    setColor(GL_AMBIENT, Eigen::Vector3d::Zero());
    setColor(GL_SPECULAR, s.sun.color * s.sun.intensity / kHeadroom);
    glEnable(GL_COLOR_MATERIAL);
    glColorMaterial(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE);
    // The previous frame's highlight pass left its specular colour in the material.
    const GLfloat black[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, black);
}

// A translucent sheet passes part of the sun to its far side: a second light from the opposite
// direction, which two-sided lighting applies to the face turned away from the sun.
void setupTransmittedSun(const RenderSettings& s, double transmission) {
    if (transmission <= 0.0) return;
    const Eigen::Vector3d d = -s.sun.direction.normalized();
    const GLfloat position[4] = {float(d.x()), float(d.y()), float(d.z()), 0.0f};
    const Eigen::Vector3d c = s.sun.color * s.sun.intensity * transmission / kHeadroom;
    const GLfloat color[4] = {float(c.x()), float(c.y()), float(c.z()), 1.0f};
    const GLfloat black[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    glEnable(GL_LIGHT1);
    glLightfv(GL_LIGHT1, GL_POSITION, position);
    glLightfv(GL_LIGHT1, GL_DIFFUSE, color);
    glLightfv(GL_LIGHT1, GL_AMBIENT, black);
    glLightfv(GL_LIGHT1, GL_SPECULAR, black);
}

void setupFog(const RenderSettings& s) {
    const double dist = cameraDistance(s.camera);
    const Eigen::Vector3d fog = s.background / kHeadroom;
    const GLfloat color[4] = {float(fog.x()), float(fog.y()), float(fog.z()), 1.0f};
    glEnable(GL_FOG);
    glFogi(GL_FOG_MODE, GL_LINEAR);
    glFogfv(GL_FOG_COLOR, color);
    glFogf(GL_FOG_START, float(kFogStart * dist));
    glFogf(GL_FOG_END, float(kFogEnd * dist));
}

void drawGround(const RenderSettings& s) {
    const double half = kGroundExtent * cameraDistance(s.camera);
    const double step = 2.0 * half / kGroundCells;
    const double x0 = s.camera.lookAt.x() - half;
    const double y0 = s.camera.lookAt.y() - half;
    const double z = s.groundHeight;
    glColor3d(s.groundColor.x(), s.groundColor.y(), s.groundColor.z());
    glNormal3d(0.0, 0.0, 1.0);
    for (int j = 0; j < kGroundCells; ++j) {
        glBegin(GL_QUAD_STRIP);
        for (int i = 0; i <= kGroundCells; ++i) {
            // This vertex order winds the strip counter-clockwise seen from above, so the front
            // face (the one two-sided lighting lights with the given normal) faces up.
            glVertex3d(x0 + i * step, y0 + (j + 1) * step, z);
            glVertex3d(x0 + i * step, y0 + j * step, z);
        }
        glEnd();
    }
}

/// Per-vertex shading of the mesh, each vertex's Shading from its colour and, where the look's
/// layer is on, its layer: what the diffuse and the specular pass draw with.
struct VertexShading {
    std::vector<Eigen::Vector3f> diffuse;
    std::vector<Eigen::Vector3f> specular;  ///< peak of a normalised lobe, at 1 / kHeadroom
    float shininess = 1.0f;                 ///< one exponent per pass: the glossiest vertex's
    bool glossy = false;                    ///< whether any vertex has a highlight
};

/// The Blinn-Phong exponent equivalent to GGX alpha (Walter et al. 2007: n = 2 / alpha^2 - 2),
/// capped at GL's limit.
float phongExponent(float roughness) {
    const float alpha = std::max(roughness * roughness, 1e-3f);
    return std::clamp(2.0f / (alpha * alpha) - 2.0f, 1.0f, kMaxShininess);
}

VertexShading vertexShading(const Mesh& mesh, const RenderSettings& s) {
    const Shading base = baseShading(s);
    const std::size_t n = mesh.positions.size();
    VertexShading out;
    out.diffuse.resize(n);
    out.specular.resize(n);
    for (std::size_t v = 0; v < n; ++v) {
        Shading here = base;
        if (v < mesh.layers.size())
            here = layeredShading(s.look, base, mesh.layers[v].x(), mesh.layers[v].y());
        if (v < mesh.colors.size()) here.color = mesh.colors[v];
        const bool metal = here.metalness() > 0.0f;
        // A film's transmitted light passes straight through rather than scattering; a
        // translucent sheet's comes back out on both sides, which the preview's weak ambient
        // light would otherwise miss, so only film loses it.
        const float kept = here.kind == MaterialKind::Film
                               ? 1.0f - std::clamp(here.transmission, 0.0f, 1.0f)
                               : 1.0f;
        out.diffuse[v] = metal ? Eigen::Vector3f(kMetalDiffuse * here.color) : here.color * kept;
        const float exponent = phongExponent(here.roughness);
        // The lobe's peak (n + 8) / (8 pi) keeps a rough surface's highlight dim and broad.
        const float peak = (exponent + 8.0f) / (8.0f * std::numbers::pi_v<float>);
        // As in the path tracer, only metal and film have a glossy lobe.
        const bool glossy = metal || here.kind == MaterialKind::Film;
        const Eigen::Vector3f f0 =
            metal ? here.color : Eigen::Vector3f::Constant(glossy ? kDielectricF0 : 0.0f);
        out.specular[v] = (peak / float(kHeadroom)) * f0;
        if (!glossy) continue;
        out.shininess = std::max(out.shininess, exponent);
        out.glossy = true;
    }
    return out;
}

void drawTriangles(const Mesh& mesh, const std::vector<Eigen::Vector3f>& colors) {
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_NORMAL_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    glVertexPointer(3, GL_FLOAT, sizeof(Eigen::Vector3f), mesh.positions.data());
    glNormalPointer(GL_FLOAT, sizeof(Eigen::Vector3f), mesh.normals.data());
    glColorPointer(3, GL_FLOAT, sizeof(Eigen::Vector3f), colors.data());
    glDrawElements(GL_TRIANGLES, GLsizei(mesh.triangles.size() * 3), GL_UNSIGNED_INT,
                   mesh.triangles.data());
    glDisableClientState(GL_COLOR_ARRAY);
    glDisableClientState(GL_NORMAL_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
}

/// Highlights drawn over the lit sheet: the same triangles with only the specular term, added.
/// Fixed-function GL tracks one material colour per vertex, so the diffuse and the specular
/// colours need a pass each.
void drawHighlights(const Mesh& mesh, const VertexShading& shading) {
    const GLfloat black[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    glColorMaterial(GL_FRONT_AND_BACK, GL_SPECULAR);
    glMaterialfv(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE, black);
    glMaterialf(GL_FRONT_AND_BACK, GL_SHININESS, shading.shininess);
    glFogfv(GL_FOG_COLOR, black);  // fog fades a highlight out rather than adding haze twice
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_FALSE);
    drawTriangles(mesh, shading.specular);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    glDisable(GL_BLEND);
}

/// A collider's look as the sheet's shading would give it: Lambert, or a metal with the same
/// stand-in diffuse and normalised lobe as a metal sheet.
VertexShading colliderShading(const Mesh& mesh, const ColliderLook& look) {
    const Eigen::Vector3f color = look.color.cast<float>().cwiseMax(0.0f).cwiseMin(1.0f);
    const float exponent = phongExponent(float(look.roughness));
    const float peak = (exponent + 8.0f) / (8.0f * std::numbers::pi_v<float>);
    const std::size_t n = mesh.positions.size();
    VertexShading out;
    out.diffuse.assign(n, look.metal ? Eigen::Vector3f(kMetalDiffuse * color) : color);
    out.specular.assign(n, (peak / float(kHeadroom)) * color);
    out.shininess = exponent;
    out.glossy = look.metal;
    return out;
}

void drawColliders(std::span<const Mesh> colliders, const RenderSettings& s) {
    for (std::size_t c = 0; c < colliders.size(); ++c) {
        if (colliders[c].triangles.empty()) continue;
        const VertexShading shading = colliderShading(colliders[c], s.colliderLook(c));
        drawTriangles(colliders[c], shading.diffuse);
        if (!shading.glossy) continue;
        drawHighlights(colliders[c], shading);
        setupLighting(s);  // the highlight pass changed the material and the fog colour
        setupFog(s);
    }
}

void drawMesh(const Mesh& mesh, const RenderSettings& s) {
    if (mesh.triangles.empty()) return;
    const VertexShading shading = vertexShading(mesh, s);
    setupTransmittedSun(s, s.pathTracing.transmission);
    drawTriangles(mesh, shading.diffuse);
    glDisable(GL_LIGHT1);
    if (shading.glossy) drawHighlights(mesh, shading);
}

}  // namespace

struct OsmesaRenderer::Impl {
    OSMesaContext context = nullptr;
    std::vector<float> buffer;  ///< RGBA float, bottom row first
    int width = 0;
    int height = 0;

    void makeCurrent(int w, int h);
    Eigen::Vector3d blockMean(int x, int y, int ss) const;  ///< linear mean of one output pixel
    Image resolve(int outWidth, int outHeight, int ss, const ToneMapping& tone) const;
};

void OsmesaRenderer::Impl::makeCurrent(int w, int h) {
    if (w != width || h != height || buffer.empty()) {
        buffer.assign(std::size_t(w) * h * 4, 0.0f);
        width = w;
        height = h;
    }
    // Re-binding every call is cheap and keeps several renderers in one thread independent.
    if (!OSMesaMakeCurrent(context, buffer.data(), GL_FLOAT, w, h))
        throw std::runtime_error("OSMesaMakeCurrent failed for a float RGBA buffer");
}

Eigen::Vector3d OsmesaRenderer::Impl::blockMean(int x, int y, int ss) const {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int sy = 0; sy < ss; ++sy) {
        // OSMesa rows run bottom-up; Image rows run top-down.
        const int row = height - 1 - (y * ss + sy);
        const float* p = &buffer[(std::size_t(row) * width + std::size_t(x) * ss) * 4];
        for (int sx = 0; sx < ss; ++sx, p += 4) sum += Eigen::Vector3d(p[0], p[1], p[2]);
    }
    return sum / double(ss * ss);
}

Image OsmesaRenderer::Impl::resolve(int outWidth, int outHeight, int ss,
                                    const ToneMapping& tone) const {
    Image image{outWidth, outHeight,
                std::vector<std::uint8_t>(std::size_t(outWidth) * outHeight * 3)};
    std::vector<double> row(std::size_t(outWidth) * 3);  // a row's linear channels
    for (int y = 0; y < outHeight; ++y) {
        for (int x = 0; x < outWidth; ++x) {
            const Eigen::Vector3d c = blockMean(x, y, ss);
            for (int k = 0; k < 3; ++k) row[std::size_t(x) * 3 + k] = kHeadroom * c[k];
        }
        displayBytes(row, std::span(image.rgb).subspan(std::size_t(y) * outWidth * 3, row.size()),
                     tone);
    }
    return image;
}

OsmesaRenderer::OsmesaRenderer() : impl_(std::make_unique<Impl>()) {
    impl_->context = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, nullptr);
    if (!impl_->context) throw std::runtime_error("OSMesaCreateContextExt failed");
    try {
        impl_->makeCurrent(1, 1);
    } catch (...) {
        // The destructor does not run for a half-constructed object.
        OSMesaDestroyContext(impl_->context);
        throw;
    }
}

OsmesaRenderer::~OsmesaRenderer() {
    if (impl_ && impl_->context) OSMesaDestroyContext(impl_->context);
}

Image OsmesaRenderer::render(const Mesh& mesh, const RenderSettings& settings,
                             std::span<const Mesh> colliders) {
    if (settings.width <= 0 || settings.height <= 0)
        throw std::invalid_argument("OsmesaRenderer: image size must be positive");
    checkMesh(mesh, "OsmesaRenderer");
    for (const Mesh& collider : colliders) checkMesh(collider, "OsmesaRenderer (a collider)");
    const int ss = std::max(1, settings.supersample);
    const int w = settings.width * ss;
    const int h = settings.height * ss;
    impl_->makeCurrent(w, h);
    glViewport(0, 0, w, h);
    const Eigen::Vector3d bg = settings.background / kHeadroom;
    glClearColor(float(bg.x()), float(bg.y()), float(bg.z()), 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glShadeModel(GL_SMOOTH);
    loadCamera(settings, w, h);
    setupLighting(settings);
    setupFog(settings);
    if (settings.ground) drawGround(settings);
    drawColliders(colliders, settings);
    drawMesh(mesh, settings);
    glFinish();
    return impl_->resolve(settings.width, settings.height, ss, settings.tone);
}

std::string OsmesaRenderer::glDescription() {
    impl_->makeCurrent(std::max(impl_->width, 1), std::max(impl_->height, 1));
    const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    return std::string(renderer ? renderer : "unknown") + ", " + (version ? version : "unknown");
}

}  // namespace rend::render
