#pragma once
// Every solver a scene can name, in one table: its name, a one-line model, its source, what it
// supports and its factory. The scene loader (names, refusals), `rend --help` and the README's
// solver table read it; adding a solver is its own file pair plus one line in
// SolverRegistry.cpp.

#include <Eigen/Core>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "sim/Bonds.h"
#include "sim/Lattice.h"
#include "sim/Material.h"
#include "sim/Params.h"
#include "sim/Solver.h"

namespace rend::sim {

/// What a solver takes beyond the common core (notches, theta coupling, both integrators).
struct SolverSupport {
    bool bondLaws = false;              ///< the power law and elastoplastic law, not only linear
    bool fracture = false;              ///< breaks by a critical strain from fracture_energy
    bool sphere = false;                ///< shape = "sphere": a closed, curved rest sheet
    bool paperCriticalStretch = false;  ///< critical_stretch = "paper" (eq. 28 as printed)
    bool surfaceCorrection = false;     ///< surface_correction = true
    bool materialMaps = false;          ///< maps of E and fracture_energy (density: every one)
    bool remesh = false;                ///< remesh = { every = N } (seed 004, sim/Remesh.h)
    bool lawMaps = false;               ///< maps of the bond law's yield_strain
};

/// What a factory builds a solver from: the scene, its validated material, the rest lattice,
/// and the Membrane's bonds, rest positions and particle volumes (all outlive the solver).
struct SolverSetUp {
    const MembraneParams& params;
    const Material& material;
    const Lattice& lattice;
    const BondFamilies& bonds;
    std::span<const Eigen::Vector3d> rest;
    std::span<const double> volumes;
};

struct SolverEntry {
    std::string_view name;    ///< the scene's `solver = "..."`
    std::string_view model;   ///< one line, for --help and the README
    std::string_view source;  ///< the paper it follows
    SolverSupport supports;
    std::unique_ptr<Solver> (*make)(const SolverSetUp&);
};

/// The solvers, the default (peridynamic) first.
std::span<const SolverEntry> solverRegistry();

/// The entry named `name`, or nullptr.
const SolverEntry* findSolver(std::string_view name);

/// The entry named `name`; throws std::invalid_argument naming the solvers there are.
const SolverEntry& solverEntry(std::string_view name);

/// What `params` asks of its solver that the solver lacks, as "a, b and c"; empty when nothing.
std::string unsupportedFeatures(const SolverEntry& solver, const MembraneParams& params);

/// The solvers' names in registry order (what the scene schema offers for `solver`).
std::span<const std::string_view> solverNames();

/// "peridynamic, fem_cst, ..." in registry order.
std::string solverNameList();

/// The registry as the README's Markdown table (| solver | model | takes | source |).
std::string solverTableMarkdown();

}  // namespace rend::sim
