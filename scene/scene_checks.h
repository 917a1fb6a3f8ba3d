// Likely mistakes in a loaded scene that do not stop a run, found against the frames it will
// run: a moving body whose sequence ends before the run does (it would stand still), a body
// modelled in centimetres beside cloth in metres, a collider nowhere near any cloth or hair.
// Each is a warning at the collider's place in the scene file.
#pragma once

#include "scene/sim_scene.h"

#include <memory>
#include <vector>

namespace gale::scene {

// The warnings of running `scene` from frame `first` to `last` with `bodies` (buildBodies').
std::vector<SceneError> runWarnings(const SimScene& scene,
                                    const std::vector<std::unique_ptr<solver::Body>>& bodies,
                                    int first, int last);

} // namespace gale::scene
