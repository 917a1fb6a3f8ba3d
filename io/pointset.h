// Point sets as named double columns, read from and written to CSV, PLY (ascii and binary,
// arbitrary vertex properties), OBJ (vertices, via tinyobjloader), JSON and NPY.
// Library code: errors come back as IoError values, nothing is printed.
#pragma once

#include <cstddef>
#include <iosfwd>
#include <string>
#include <vector>

namespace gale::io {

struct PointSet {
    std::vector<std::string> names;           // column names, in file order
    std::vector<std::vector<double>> columns; // all of the same length
    std::vector<std::vector<int>> faces;      // polygon faces (PLY face element / OBJ f), kept
    bool plyBinary = false;                   // read from a binary PLY
    // Per column (may be shorter than `columns`; a missing entry is false): the values are
    // float32 (a PLY float property, a float-precision result). Text writers then print the
    // shortest decimal that round-trips the float (0.1, not 0.10000000149011612).
    std::vector<bool> float32;

    bool isFloat32(int column) const {
        return column >= 0 && static_cast<size_t>(column) < float32.size() && float32[column];
    }

    size_t size() const { return columns.empty() ? 0 : columns[0].size(); }
    int find(const std::string& name) const; // column index or -1
    // Adds a column of size() zeros (or replaces one of that name); returns its index.
    int addColumn(const std::string& name);
};

struct IoError {
    enum Kind { None, Io, Data } kind = None; // Io: cannot open/read/write; Data: malformed
    std::string file;
    int line = 0; // 1-based, 0 when unknown
    int col = 0;
    std::string message; // what is wrong and what to do

    explicit operator bool() const { return kind != None; }
    // "file:line:col: error: message" (line/col left out when unknown).
    std::string render() const;
    // "file:line:col: message": for a caller's own diagnostic, which says "error:" itself.
    std::string brief() const;
};

enum class PointFormat { Csv, Ply, PlyAscii, Obj, Json, Npy };

// Format from a file name's extension (.csv .ply .obj .json .npy); false if unknown.
bool formatFromPath(const std::string& path, PointFormat& out);

// Read by extension; "-" reads CSV from `stdinStream` (pass std::cin).
IoError readPoints(const std::string& path, PointSet& out, std::istream* stdinStream = nullptr);
IoError readPointsCsv(std::istream& in, const std::string& displayName, PointSet& out);
IoError readPointsPly(std::istream& in, const std::string& displayName, PointSet& out);
IoError readPointsObj(const std::string& path, PointSet& out);

// Reads a CSV point file a chunk of rows at a time, so a file of any length is read in
// bounded memory; the errors (and their line numbers) are readPointsCsv's, which uses it.
class CsvPointReader {
public:
    CsvPointReader(std::istream& in, std::string displayName);
    // Reads up to and including the header: `out` gets its column names and no rows.
    IoError readHeader(PointSet& out);
    // Resets `chunk` to the header's columns (dropping any added since, clearing float32) and
    // fills it with up to `maxRows` rows; it has no rows at the end of the input.
    IoError readRows(PointSet& chunk, size_t maxRows);

private:
    std::istream& mIn;
    std::string mName;
    std::string mLine;
    std::vector<std::string> mNames;
    int mLineNo = 0;
    int mHeaderLine = 0;
};

// Writers. Ply writes binary little-endian, PlyAscii ascii — every column as a `float`
// property (what Houdini and Blender expect), plus a face element when there are faces.
// Npy writes the columns listed in `npyColumns` (empty: all) as a little-endian float32 array
// of shape (N, len) — or (N,) for one column. Json writes an array with one object per point
// (NaN and infinities as null). Obj writes `v x y z` and `f` lines (other columns dropped).
IoError writePoints(std::ostream& out, const PointSet& points, PointFormat format,
                    const std::vector<int>& npyColumns = {});
// The CSV writer's rows, with the header line first when `header`: writing the header with
// the first chunk of rows and the rest without gives the bytes of one writePoints call.
IoError writePointsCsv(std::ostream& out, const PointSet& points, bool header);
// Write to a temporary file in the same folder, then rename over `path`: never half-written.
IoError writePointsFile(const std::string& path, const PointSet& points, PointFormat format,
                        const std::vector<int>& npyColumns = {});

// Shortest decimal that round-trips (std::to_chars): 7, 0.1, 1e-07, -0, nan, inf.
std::string formatNumber(double v);

// A JSON string literal: quotes, backslashes and control characters escaped.
std::string jsonString(const std::string& s);

// Host variables a point set provides: (x,y,z) -> P, (nx,ny,nz) -> N, every other column a
// scalar of its own name (characters outside [A-Za-z0-9_.] become '_', a name that does not
// start with a letter or '_' gets a leading '_'). When two columns map to the same name, the
// first one (P and N before the rest) wins and the other is left out.
struct PointVariable {
    std::string name;
    std::vector<int> columns; // column index per component
};
std::vector<PointVariable> pointVariables(const PointSet& points);

} // namespace gale::io
