#include "render/OsmesaRenderer.h"

#include <GL/osmesa.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "render/GlMath.h"

namespace rend::render {

namespace {

// Output encoding: GL shades in linear space into a float buffer, and the box-filtered result
// is encoded with a plain 2.2 gamma. Filtering before encoding keeps edges from darkening,
// and the float buffer avoids banding in the shadows that an 8-bit linear buffer would cause.
constexpr double kGamma = 2.2;

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
    const GLfloat ambient[4] = {float(s.ambient), float(s.ambient), float(s.ambient), 1.0f};
    glLightModelfv(GL_LIGHT_MODEL_AMBIENT, ambient);
    // Issued after the view matrix is loaded, so the direction is taken in world space.
    const Eigen::Vector3d d = s.sun.direction.normalized();
    const GLfloat position[4] = {float(d.x()), float(d.y()), float(d.z()), 0.0f};
    glLightfv(GL_LIGHT0, GL_POSITION, position);
    setColor(GL_DIFFUSE, s.sun.color * s.sun.intensity);
    setColor(GL_AMBIENT, Eigen::Vector3d::Zero());
    setColor(GL_SPECULAR, Eigen::Vector3d::Zero());
    glEnable(GL_COLOR_MATERIAL);
    glColorMaterial(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE);
}

void setupFog(const RenderSettings& s) {
    const double dist = cameraDistance(s.camera);
    const GLfloat color[4] = {float(s.background.x()), float(s.background.y()),
                              float(s.background.z()), 1.0f};
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

void drawMesh(const Mesh& mesh, const RenderSettings& s) {
    if (mesh.triangles.empty()) return;
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_NORMAL_ARRAY);
    glVertexPointer(3, GL_FLOAT, sizeof(Eigen::Vector3f), mesh.positions.data());
    glNormalPointer(GL_FLOAT, sizeof(Eigen::Vector3f), mesh.normals.data());
    if (mesh.colors.empty()) {
        glColor3d(s.albedo.x(), s.albedo.y(), s.albedo.z());
    } else {
        glEnableClientState(GL_COLOR_ARRAY);
        glColorPointer(3, GL_FLOAT, sizeof(Eigen::Vector3f), mesh.colors.data());
    }
    glDrawElements(GL_TRIANGLES, GLsizei(mesh.triangles.size() * 3), GL_UNSIGNED_INT,
                   mesh.triangles.data());
    glDisableClientState(GL_COLOR_ARRAY);
    glDisableClientState(GL_NORMAL_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
}

std::uint8_t encode(double linear) {
    const double c = std::pow(std::clamp(linear, 0.0, 1.0), 1.0 / kGamma);
    return static_cast<std::uint8_t>(std::lround(c * 255.0));
}

}  // namespace

struct OsmesaRenderer::Impl {
    OSMesaContext context = nullptr;
    std::vector<float> buffer;  ///< RGBA float, bottom row first
    int width = 0;
    int height = 0;

    void makeCurrent(int w, int h);
    Eigen::Vector3d blockMean(int x, int y, int ss) const;  ///< linear mean of one output pixel
    Image resolve(int outWidth, int outHeight, int ss) const;
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

Image OsmesaRenderer::Impl::resolve(int outWidth, int outHeight, int ss) const {
    Image image{outWidth, outHeight,
                std::vector<std::uint8_t>(std::size_t(outWidth) * outHeight * 3)};
    for (int y = 0; y < outHeight; ++y) {
        for (int x = 0; x < outWidth; ++x) {
            const Eigen::Vector3d c = blockMean(x, y, ss);
            std::uint8_t* out = &image.rgb[(std::size_t(y) * outWidth + x) * 3];
            for (int k = 0; k < 3; ++k) out[k] = encode(c[k]);
        }
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

Image OsmesaRenderer::render(const Mesh& mesh, const RenderSettings& settings) {
    if (settings.width <= 0 || settings.height <= 0)
        throw std::invalid_argument("OsmesaRenderer: image size must be positive");
    checkMesh(mesh, "OsmesaRenderer");
    const int ss = std::max(1, settings.supersample);
    const int w = settings.width * ss;
    const int h = settings.height * ss;
    impl_->makeCurrent(w, h);
    glViewport(0, 0, w, h);
    const auto& bg = settings.background;
    glClearColor(float(bg.x()), float(bg.y()), float(bg.z()), 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glShadeModel(GL_SMOOTH);
    loadCamera(settings, w, h);
    setupLighting(settings);
    setupFog(settings);
    if (settings.ground) drawGround(settings);
    drawMesh(mesh, settings);
    glFinish();
    return impl_->resolve(settings.width, settings.height, ss);
}

std::string OsmesaRenderer::glDescription() {
    impl_->makeCurrent(std::max(impl_->width, 1), std::max(impl_->height, 1));
    const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    return std::string(renderer ? renderer : "unknown") + ", " + (version ? version : "unknown");
}

}  // namespace rend::render
