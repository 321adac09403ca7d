#include "sim/SolverRegistry.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <vector>

#include "sim/FemCst.h"
#include "sim/MassSpring.h"
#include "sim/Mpm.h"
#include "sim/PeridynamicBonds.h"
#include "sim/TotalLagrangianSph.h"

namespace rend::sim {
namespace {

// One line per solver. SolverSupport: {bondLaws, fracture, sphere, paperCriticalStretch,
// surfaceCorrection, materialMaps, remesh, lawMaps}.
constexpr std::array kSolvers{
    SolverEntry{"peridynamic",
                "bond forces (eqs. 18-20), fracture, diffusion coupling",
                "membrane paper",
                {true, true, true, true, true, true, true, true},
                &PeridynamicBonds::make},
    SolverEntry{"fem_cst",
                "constant-strain triangles, St. Venant-Kirchhoff in plane stress (the exact "
                "gradient of the energy); the power law and elastoplastic law on the principal "
                "stretches",
                "seminar report",
                {true, true, true, false, false, true, false, true},
                &FemCst::make},
    SolverEntry{"mass_spring_vg",
                "one spring per triangle edge, Van Gelder's k (eq. 1)",
                "mass-spring paper",
                {true, true, true, false, false, true, false, true},
                &MassSpring::makeVanGelder},
    SolverEntry{"mass_spring_tp",
                "two-parameter springs: fixed Q (eq. 12) x variable q (eq. 14), from the sides' "
                "and heights' strains",
                "mass-spring paper",
                {true, true, true, false, false, true, false, true},
                &MassSpring::makeTwoParameter},
    SolverEntry{"sph",
                "kernel-corrected total-Lagrangian SPH (rest neighbours within 2 dx), St. "
                "Venant-Kirchhoff as the FEM; fracture by damage-weighted pairs",
                "membrane paper, Sec. 6.1",
                {false, true, false, false, false, true, true},
                &TotalLagrangianSph::make},
    SolverEntry{"mpm",
                "codimensional MPM: the FEM's lattice forces, momentum through a 3D grid with "
                "APIC; particles near material boundaries and cracks solved on their own domains",
                "enhanced MPM paper (seed 002)",
                {true, true, true, false, false, true, false, true},
                &Mpm::make},
};

std::string joined(const std::vector<std::string>& items, std::string_view last) {
    std::string out;
    for (std::size_t k = 0; k < items.size(); ++k)
        out += (k == 0 ? "" : k + 1 == items.size() ? std::string(last) : ", ") + items[k];
    return out;
}

}  // namespace

constexpr auto kNames = [] {
    std::array<std::string_view, kSolvers.size()> names{};
    for (std::size_t k = 0; k < names.size(); ++k) names[k] = kSolvers[k].name;
    return names;
}();

std::span<const SolverEntry> solverRegistry() { return kSolvers; }

std::span<const std::string_view> solverNames() { return kNames; }

const SolverEntry* findSolver(std::string_view name) {
    const auto it = std::find_if(kSolvers.begin(), kSolvers.end(),
                                 [&](const SolverEntry& e) { return e.name == name; });
    return it == kSolvers.end() ? nullptr : &*it;
}

const SolverEntry& solverEntry(std::string_view name) {
    if (const SolverEntry* entry = findSolver(name)) return *entry;
    throw std::invalid_argument("no solver is named \"" + std::string(name) +
                                "\"; the solvers are " + solverNameList());
}

std::string unsupportedFeatures(const SolverEntry& solver, const MembraneParams& params) {
    const MaterialParams& m = params.material;
    const SolverSupport& can = solver.supports;
    std::vector<std::string> wanted;
    if (m.law != BondLawKind::Linear && !can.bondLaws)
        wanted.push_back("a bond law other than linear");
    if (m.fractureEnergy && !can.fracture) wanted.push_back("fracture_energy");
    if (m.criticalStretch == CriticalStretchMode::Paper && !can.paperCriticalStretch)
        wanted.push_back("critical_stretch = \"paper\"");
    if (params.sheet.outline == Outline::Sphere && !can.sphere)
        wanted.push_back("shape = \"sphere\"");
    if (m.surfaceCorrection && !can.surfaceCorrection) wanted.push_back("surface_correction");
    if (!can.materialMaps && (mapsProperty(params.materialMaps, MappedProperty::YoungsModulus) ||
                              mapsProperty(params.materialMaps, MappedProperty::FractureEnergy)))
        wanted.push_back("a material map of E or fracture_energy");
    if (params.remesh.every > 0 && !can.remesh) wanted.push_back("remesh");
    if (!can.lawMaps && mapsLaw(params.materialMaps))
        wanted.push_back(
            "a material map of the bond law (yield_strain, softening, power_ratio, "
            "power_exponent)");
    if (params.remesh.every > 0 && params.sheet.outline == Outline::Sphere)
        wanted.push_back("remesh on a sphere (it remeshes in the flat rest plane)");
    return joined(wanted, " and ");
}

std::string solverNameList() {
    std::vector<std::string> names;
    for (const SolverEntry& e : kSolvers) names.emplace_back(e.name);
    return joined(names, ", ");
}

std::string solverTableMarkdown() {
    std::string out = "| solver | model | takes beyond linear bonds and notches | source |\n";
    out += "|---|---|---|---|\n";
    for (const SolverEntry& e : kSolvers) {
        const SolverSupport& can = e.supports;
        std::vector<std::string> takes;
        if (can.bondLaws) takes.push_back("bond laws");
        if (can.fracture) takes.push_back("fracture");
        if (can.sphere) takes.push_back("sphere");
        if (can.materialMaps) takes.push_back("material maps");
        if (can.lawMaps)
            takes.push_back("bond-law maps (yield_strain, softening, power_ratio, power_exponent)");
        if (can.remesh) takes.push_back("`remesh`");
        if (can.paperCriticalStretch) takes.push_back("`critical_stretch = \"paper\"`");
        if (can.surfaceCorrection) takes.push_back("`surface_correction`");
        out += "| `" + std::string(e.name) + "` | " + std::string(e.model) + " | " +
               joined(takes, ", ") + " | " + std::string(e.source) + " |\n";
    }
    return out;
}

}  // namespace rend::sim
