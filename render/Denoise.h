#pragma once
// A denoiser for the path tracer's few-sample frames: the edge-avoiding a-trous wavelet filter
// (Dammertz, Sewtz, Hanika & Lensch 2010) with the variance-guided colour weight of SVGF
// (Schied et al. 2017, spatial part). Each pass blurs with a 3 x 3 B-spline kernel whose taps
// lie 2^i pixels apart, weighted down across a change of surface (normal), of distance (depth,
// against its own slope) and of brightness beyond what the pixel's noise explains. The light
// is filtered apart from the surface colour (demodulated by the first hit's albedo), so the heat
// tint, the damp patches and the ground's shade stay sharp while their noise goes.
//
// A pure function of its inputs, pixel by pixel in each pass: any thread count gives the same
// bytes.

#include <memory>
#include <vector>

namespace rend::render {

/// What the filter keeps edges by, per pixel, top row first (from each pixel's centre ray).
struct DenoiseGuides {
    int width = 0;
    int height = 0;
    std::vector<float> albedo;  ///< 3 per pixel: the first hit's colour; 1 where none
    std::vector<float> normal;  ///< 3 per pixel: unit; 0 where no hit
    std::vector<float> depth;   ///< per pixel [m]; FrameLayers::kNoHit where no hit
    /// Per pixel: the variance of the pixel's mean luminance. Empty (one sample per pixel):
    /// estimated from the spread over each pixel's neighbours.
    std::vector<float> variance;
};

/// The number of a-trous passes: taps 1, 2, 4, 8, 16 pixels apart, a footprint of 63 pixels.
inline constexpr int kDenoisePasses = 5;

/// Filters linear radiance `rgb` (3 per pixel) in place. Throws std::invalid_argument when the
/// guides' sizes do not match the image.
void denoise(std::vector<float>& rgb, const DenoiseGuides& guides, int passes = kDenoisePasses);

/// denoise() that keeps its buffers (about 100 bytes a pixel) from one frame to the next: a
/// fresh 200 MB each 1080p frame costs as much in page faults as a filter pass.
class Denoiser {
public:
    Denoiser();
    ~Denoiser();
    Denoiser(const Denoiser&) = delete;
    Denoiser& operator=(const Denoiser&) = delete;

    void operator()(std::vector<float>& rgb, const DenoiseGuides& guides,
                    int passes = kDenoisePasses);

private:
    struct Workspace;
    std::unique_ptr<Workspace> workspace_;
};

}  // namespace rend::render
