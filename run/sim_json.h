// A run's settings and per-frame statistics as JSON, the text of run.json (and of the Python
// module's frame stats): the scene as resolved after --set, and each frame's substeps, solver
// iterations, residuals, speeds, energies and events.
#pragma once

#include "scene/sim_scene.h"
#include "solver/world/world.h"

#include <memory>
#include <string>
#include <vector>

namespace gale::run {

// The settings as resolved (after --set) for frames first..last, run.json's "settings" (and
// what --resume compares to continue only the same run).
std::string settingsJson(const scene::SimScene& scene,
                         const std::vector<std::unique_ptr<solver::Body>>& bodies, int first,
                         int last, int threads);

// One frame's statistics, an element of run.json's "frames".
std::string frameJson(const solver::FrameStats& stats);

// The frame's stats of the initial state (no substeps taken) at `frame`, time `t` (s).
solver::FrameStats initialStats(const solver::World& world, int frame, double t);

} // namespace gale::run
