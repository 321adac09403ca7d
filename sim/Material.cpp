#include "sim/Material.h"

#include <stdexcept>

namespace rend::sim {

Material::Material(const MaterialParams& params) : params_(params) {
    const double E = params.youngsModulus, nu = params.poissonRatio;
    if (!(E > 0.0)) throw std::invalid_argument("the material needs E > 0");
    if (!(nu > -1.0 && nu < 0.5))
        throw std::invalid_argument("the material needs -1 < poisson < 0.5");
    lambda_ = E * nu / (1.0 - nu * nu);
    mu_ = E / (2.0 * (1.0 + nu));
}

}  // namespace rend::sim
