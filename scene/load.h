// The one loader of a scene file (TOML): the wind ([scene], [windicator], [[gust]], [[field]];
// fields/scene.h) and the bodies ([[cloth]], [[hair]], [[collider]], [solver]; scene/sim_scene.h),
// with `--set KEY=VALUE` overrides by dotted path. Every error carries file:line:col and, where
// a name is unknown, "did you mean". It knows fields and solver; neither knows it.
#pragma once

#include "fields/scene.h"
#include "scene/sim_scene.h"

#include <string>
#include <vector>

namespace gale::scene {

struct SceneLoadOptions {
    // `--set KEY=VALUE` overrides by dotted path (`windicator.speed=12`, `field.main.params.swirl=0.3`,
    // `scene.fps=30`); an unknown path is an error.
    std::vector<std::string> sets;
    // Top-level sections left to the bodies' half of the loader; any other unknown key is an
    // error.
    std::vector<std::string> foreignSections{"cloth", "hair", "collider", "solver"};
};

// Reads and validates the wind part of a scene file. Errors carry file:line:col (toml++
// source regions); every problem found is reported, not just the first. Returns false when
// there were errors.
bool loadScene(const std::string& path, fields::Scene& out, std::vector<SceneError>& errors,
               const SceneLoadOptions& options = {});

// Reads the whole scene, read and parsed once: the wind's sections as loadScene does (the bodies'
// sections foreign to it), then [[cloth]], [[hair]], [[collider]] and [solver].
// `sets` are `--set KEY=VALUE` overrides by dotted path (`cloth.cape.drag=0.8`,
// `collider.0.radius=0.4`, `solver.max_halvings=4`, and the wind's own paths). Every problem
// is reported at file:line:col; false when there were errors.
bool loadSimScene(const std::string& path, SimScene& out, std::vector<SceneError>& errors,
                  const std::vector<std::string>& sets = {});

} // namespace gale::scene
