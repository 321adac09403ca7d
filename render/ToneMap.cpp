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

double filmicCurve(double x) {
    if (!(x > 0.0)) return 0.0;
    if (std::isinf(x)) return 1.0;
    const double s = kMidGreyScale * x;
    return s * (kA * s + kB) / (s * (kC * s + kD) + kE) * (kC / kA);
}

double toneMap(double linear, const ToneMapping& tone) {
    if (!(linear > 0.0)) return 0.0;
    const double x = linear * std::exp2(tone.exposure);
    return tone.curve == ToneCurve::Filmic ? filmicCurve(x) : std::min(x, 1.0);
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

}  // namespace

// The thresholds instead of pow for every channel of every pixel (4% of a rendered
// final-quality shot): a table of 4,096 bins gives the count below the value's bin, and at
// most a few more thresholds lie within it. Within a billionth of a threshold, where rounding
// could decide the other way, the byte is pow's own: the same bytes as gammaByte for any value.
std::uint8_t displayByte(double linear, const ToneMapping& tone) {
    static const ByteThresholds thresholds;
    const auto& from = thresholds.from;
    const double mapped = toneMap(linear, tone);  // in [0, 1]
    int k =
        thresholds.below[std::clamp(int(mapped * ByteThresholds::kBins), 0, ByteThresholds::kBins)];
    while (from[k + 1] <= mapped) ++k;
    const bool clearOfBelow = k == 0 || mapped - from[k] > 1e-9 * from[k];
    const bool clearOfAbove = k == 255 || from[k + 1] - mapped > 1e-9 * from[k + 1];
    return clearOfBelow && clearOfAbove ? std::uint8_t(k) : gammaByte(mapped);
}

}  // namespace rend::render
