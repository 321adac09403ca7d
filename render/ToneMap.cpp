#include "render/ToneMap.h"

#include <algorithm>
#include <cmath>

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

std::uint8_t displayByte(double linear, const ToneMapping& tone) {
    const double c = std::pow(toneMap(linear, tone), 1.0 / kGamma);
    return static_cast<std::uint8_t>(std::lround(std::clamp(c, 0.0, 1.0) * 255.0));
}

}  // namespace rend::render
