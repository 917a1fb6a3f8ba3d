// A scene file as a document: its TOML tree with source locations, for the code that edits or
// inspects a scene rather than running it — `gale wedge` applies --set overrides and writes a
// variant's scene back, `gale live` finds the files a scene names and where its literals are.
// toml++ stays inside scene/: callers see only this class.
#pragma once

#include "scene/error.h"

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace gale::scene {

// Where a value is written in the scene file: 1-based line and column (columns count code
// points), and its bytes [begin, end) in the file's text.
struct SourceSpan {
    int line = 0, col = 0;
    size_t begin = 0, end = 0;
};

class SceneDocument {
public:
    SceneDocument();
    ~SceneDocument();
    SceneDocument(SceneDocument&&) noexcept;
    SceneDocument& operator=(SceneDocument&&) noexcept;

    // Reads and parses `path` (or parses `text` as that file). False, with the error (an
    // unreadable file, marked io, or the syntax error at its file:line:col), when either fails.
    bool read(const std::string& path, std::vector<SceneError>& errors);
    bool parse(const std::string& path, const std::string& text, std::vector<SceneError>& errors);

    const std::string& path() const;
    const std::string& text() const; // the file as read (edits do not change it)

    // Applies `--set KEY=VALUE` overrides by dotted path, exactly as loadSimScene applies them
    // (every section: scene, windicator, solver, gust, field, cloth, hair, collider). Each
    // override that cannot be applied is an error naming it; false when there were any.
    bool applySets(const std::vector<std::string>& sets, std::vector<SceneError>& errors);

    // The key of a `--set KEY=VALUE` (the part before '='), with a [[gust]], [[field]], [[cloth]],
    // [[hair]] or [[collider]] entry named by its index as applySets resolves it (by name, the
    // default `cloth0`-style names, or its index): `cloth.cape.stretch` and `cloth.0.stretch`
    // give one key for the same entry. Otherwise the key as written (trimmed).
    std::string canonicalSetKey(const std::string& set) const;

    // Every relative file name the scene's schema knows (a field's expr, a cloth's mesh and
    // rest_mesh, a hair's strands, painted-map exprs, a collider's mesh, an attachment's mesh)
    // made absolute against the scene's folder, so that the document can be written elsewhere.
    void absolutisePaths();

    // The document as TOML text: `header` as leading comment lines, then the tree (decimals as
    // typed: 15 significant digits round-trip them).
    std::string write(const std::string& header) const;

    // Every string value that names an existing regular file relative to the scene's folder
    // (or absolute), in document order: what a watcher of the scene must also watch.
    std::vector<std::string> namedFiles() const;
    // Every other string value (shorter than 1000 bytes) as a path relative to the scene's
    // folder (or absolute), in document order: names of files that may appear later (a frame
    // sequence `body/body.#.obj` whose folder is still to be written); the caller filters.
    std::vector<std::string> otherPaths() const;

    // The literal of `[[field]]` number `field` (from 0) `params.NAME` when it is a number or
    // an array of numbers (a constant override a slider can rewrite in place); nullopt for
    // keys, expressions or when absent.
    std::optional<SourceSpan> fieldParamLiteral(size_t field, const std::string& name) const;

    // `[[collider]]` number `index`'s `mesh` string as written (relative to the scene's
    // folder), or "" when it has none.
    std::string colliderMesh(size_t index) const;

private:
    struct Impl;
    std::unique_ptr<Impl> m;
};

} // namespace gale::scene
