#include "render/ToneMap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace rend::render {

namespace {

// Narkowicz 2016's coefficients. Their limit a / c = 1.033 is where the fit crosses display
// white; dividing by it moves white to infinity, so no finite highlight clips.
constexpr double kA = 2.51;
constexpr double kB = 0.03;
constexpr double kC = 2.43;
constexpr double kD = 0.59;
constexpr double kE = 0.14;
constexpr double kGamma = 2.2;
// The fit maps 0.18 to 0.26, a brighter mid-grey than the clamp it replaces; scaling its input
// by this factor (solved numerically) keeps 18% grey at 18%, so exposure 0 means what it means
// without a tone curve and only the toe and the shoulder differ.
constexpr double kMidGreyScale = 0.74152;

}  // namespace

namespace {

// filmicCurve of x > 0 (finite or not).
double filmicOfPositive(double x) {
    if (std::isinf(x)) return 1.0;
    const double s = kMidGreyScale * x;
    return s * (kA * s + kB) / (s * (kC * s + kD) + kE) * (kC / kA);
}

// toneMap with 2^exposure given.
double toneMapScaled(double linear, double scale, ToneCurve curve) {
    if (!(linear > 0.0)) return 0.0;
    const double x = linear * scale;
    if (curve != ToneCurve::Filmic) return std::min(x, 1.0);
    return x > 0.0 ? filmicOfPositive(x) : 0.0;
}

}  // namespace

double filmicCurve(double x) { return x > 0.0 ? filmicOfPositive(x) : 0.0; }

double toneMap(double linear, const ToneMapping& tone) {
    return toneMapScaled(linear, std::exp2(tone.exposure), tone.curve);
}

namespace {

std::uint8_t gammaByte(double mapped) {
    const double c = std::pow(mapped, 1.0 / kGamma);
    return static_cast<std::uint8_t>(std::lround(std::clamp(c, 0.0, 1.0) * 255.0));
}

/// from[k]: the display-linear value at which gammaByte reaches k, ((k - 1/2) / 255)^2.2; and
/// below[b]: how many of them lie at or below b / kBins.
struct ByteThresholds {
    static constexpr int kBins = 4096;
    std::array<double, 257> from{};
    std::array<std::uint8_t, kBins + 1> below{};
    ByteThresholds() {
        for (int k = 1; k < 256; ++k) from[k] = std::pow((k - 0.5) / 255.0, kGamma);
        from[256] = std::numeric_limits<double>::infinity();
        for (int b = 0; b <= kBins; ++b)
            below[b] = std::uint8_t(
                std::upper_bound(from.begin() + 1, from.begin() + 256, double(b) / kBins) -
                from.begin() - 1);
    }
};

// The thresholds instead of pow for every channel of every pixel (4% of a rendered
// final-quality shot): a table of 4,096 bins gives the count below the value's bin, and at
// most a few more thresholds lie within it. Within a billionth of a threshold, where rounding
// could decide the other way, the byte is pow's own: the same bytes as gammaByte for any value.
std::uint8_t byteOfMapped(double mapped, const ByteThresholds& thresholds) {
    const auto& from = thresholds.from;
    int k =
        thresholds.below[std::clamp(int(mapped * ByteThresholds::kBins), 0, ByteThresholds::kBins)];
    while (from[k + 1] <= mapped) ++k;
    const bool clearOfBelow = k == 0 || mapped - from[k] > 1e-9 * from[k];
    const bool clearOfAbove = k == 255 || from[k + 1] - mapped > 1e-9 * from[k + 1];
    return clearOfBelow && clearOfAbove ? std::uint8_t(k) : gammaByte(mapped);
}

}  // namespace

std::uint8_t displayByte(double linear, const ToneMapping& tone) {
    static const ByteThresholds thresholds;
    return byteOfMapped(toneMap(linear, tone), thresholds);  // in [0, 1]
}

namespace {

// 2^exposure once, and each value's curve, then its byte, in blocks: the curves' divisions of a
// block side by side rather than each behind the last one's table search (a rendered final foil
// frame has 1.6 million channels).
template <class Linear>
void bytesOf(std::span<const Linear> linear, std::span<std::uint8_t> bytes,
             const ToneMapping& tone) {
    static const ByteThresholds thresholds;
    const double scale = std::exp2(tone.exposure);
    constexpr std::size_t kBlock = 256;
    double mapped[kBlock];
    for (std::size_t first = 0; first < linear.size(); first += kBlock) {
        const std::size_t n = std::min(kBlock, linear.size() - first);
        for (std::size_t k = 0; k < n; ++k)
            mapped[k] = toneMapScaled(double(linear[first + k]), scale, tone.curve);
        for (std::size_t k = 0; k < n; ++k) bytes[first + k] = byteOfMapped(mapped[k], thresholds);
    }
}

}  // namespace

void displayBytes(std::span<const double> linear, std::span<std::uint8_t> bytes,
                  const ToneMapping& tone) {
    bytesOf(linear, bytes, tone);
}

void displayBytes(std::span<const float> linear, std::span<std::uint8_t> bytes,
                  const ToneMapping& tone) {
    bytesOf(linear, bytes, tone);
}

}  // namespace rend::render
