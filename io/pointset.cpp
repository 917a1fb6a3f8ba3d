// Point sets: CSV and OBJ readers, CSV/JSON/NPY/OBJ writers, the atomic file writer, number
// formatting and the host variables a point set provides. PLY lives in pointset_ply.cpp.
#include "io/pointset.h"

#include "io/atomic_file.h"
#include "io/pointset_detail.h"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <istream>
#include <limits>
#include <ostream>
#include <set>
#include <string_view>
#include <type_traits>
#include <unistd.h>

namespace gale::io {

using detail::dataError;
using detail::ioError;

// ---- PointSet, IoError ----

int PointSet::find(const std::string& name) const {
    for (size_t i = 0; i < names.size(); ++i)
        if (names[i] == name) return static_cast<int>(i);
    return -1;
}

int PointSet::addColumn(const std::string& name) {
    size_t n = size();
    int c = find(name);
    if (c < 0) {
        names.push_back(name);
        columns.emplace_back();
        c = static_cast<int>(names.size() - 1);
    }
    columns[c].assign(n, 0.0);
    if (static_cast<size_t>(c) < float32.size()) float32[c] = false;
    return c;
}

namespace {
std::string locationOf(const IoError& e) {
    std::string s = e.file.empty() ? std::string("<input>") : e.file;
    if (e.line > 0) {
        s += ':' + std::to_string(e.line);
        if (e.col > 0) s += ':' + std::to_string(e.col);
    }
    return s;
}
} // namespace

std::string IoError::render() const {
    return locationOf(*this) + ": error: " + message;
}

std::string IoError::brief() const {
    return locationOf(*this) + ": " + message;
}

namespace detail {

IoError dataError(const std::string& file, int line, int col, std::string message) {
    IoError e;
    e.kind = IoError::Data;
    e.file = file;
    e.line = line;
    e.col = col;
    e.message = std::move(message);
    return e;
}

IoError ioError(const std::string& file, std::string message) {
    IoError e;
    e.kind = IoError::Io;
    e.file = file;
    e.message = std::move(message);
    return e;
}

void appendNumber(std::string& out, double v, bool asFloat32) {
    if (std::isnan(v)) {
        out += "nan";
        return;
    }
    if (std::isinf(v)) {
        out += v < 0 ? "-inf" : "inf";
        return;
    }
    char buf[64];
    std::to_chars_result r = asFloat32 ? std::to_chars(buf, buf + sizeof buf, static_cast<float>(v))
                                       : std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, r.ptr);
}

} // namespace detail

std::string formatNumber(double v) {
    std::string s;
    detail::appendNumber(s, v, false);
    return s;
}

// ---- formats ----

static std::string lowerExtension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

bool formatFromPath(const std::string& path, PointFormat& out) {
    std::string ext = lowerExtension(path);
    if (ext == ".csv")
        out = PointFormat::Csv;
    else if (ext == ".ply")
        out = PointFormat::Ply;
    else if (ext == ".obj")
        out = PointFormat::Obj;
    else if (ext == ".json")
        out = PointFormat::Json;
    else if (ext == ".npy")
        out = PointFormat::Npy;
    else
        return false;
    return true;
}

static std::string errnoText(int err) {
    return err ? std::strerror(err) : "unknown error";
}

IoError readPoints(const std::string& path, PointSet& out, std::istream* stdinStream) {
    out = PointSet{};
    if (path == "-") {
        if (!stdinStream) return ioError("<stdin>", "no standard input to read points from");
        return readPointsCsv(*stdinStream, "<stdin>", out);
    }
    PointFormat format;
    if (!formatFromPath(path, format))
        return dataError(path, 0, 0, "unknown point file type: use .csv, .ply or .obj");
    if (format == PointFormat::Json || format == PointFormat::Npy)
        return dataError(path, 0, 0,
                         "points cannot be read from " + lowerExtension(path) +
                             " files: use .csv, .ply or .obj");
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        return ioError(path, "cannot read: is a directory");
    if (format == PointFormat::Obj) return readPointsObj(path, out);

    errno = 0;
    std::ifstream in(path, std::ios::binary);
    if (!in) return ioError(path, "cannot open: " + errnoText(errno));
    IoError e =
        format == PointFormat::Csv ? readPointsCsv(in, path, out) : readPointsPly(in, path, out);
    if (!e && in.bad()) return ioError(path, "read failed: " + errnoText(errno));
    return e;
}

// ---- CSV ----

namespace {

struct Field {
    std::string_view text;
    int col = 1; // 1-based byte column of the first character
};

// Splits at commas and trims spaces/tabs around each field.
void splitCsv(std::string_view line, std::vector<Field>& fields) {
    fields.clear();
    size_t start = 0;
    while (true) {
        size_t end = line.find(',', start);
        if (end == std::string_view::npos) end = line.size();
        size_t a = start, b = end;
        while (a < b && (line[a] == ' ' || line[a] == '\t')) ++a;
        while (b > a && (line[b - 1] == ' ' || line[b - 1] == '\t')) --b;
        fields.push_back({line.substr(a, b - a), static_cast<int>(a + 1)});
        if (end == line.size()) break;
        start = end + 1;
    }
}

// Parses the whole of `text` as a number (a leading '+' is allowed). Returns an error message
// or an empty string.
std::string parseNumber(std::string_view text, double& v) {
    if (text.empty()) return "expected a number, found an empty field";
    std::string_view t = text;
    if (t.size() > 1 && t[0] == '+' && t[1] != '-') t.remove_prefix(1);
    std::from_chars_result r = std::from_chars(t.data(), t.data() + t.size(), v);
    if (r.ec == std::errc::result_out_of_range)
        return "number out of range: '" + std::string(text) + "'";
    if (r.ec != std::errc() || r.ptr != t.data() + t.size())
        return "expected a number, found '" + std::string(text) + "'";
    return {};
}

} // namespace

CsvPointReader::CsvPointReader(std::istream& in, std::string displayName)
    : mIn(in), mName(std::move(displayName)) {}

IoError CsvPointReader::readHeader(PointSet& out) {
    out = PointSet{};
    std::vector<Field> fields;
    while (std::getline(mIn, mLine)) {
        ++mLineNo;
        if (!mLine.empty() && mLine.back() == '\r') mLine.pop_back();
        if (mLineNo == 1 && mLine.compare(0, 3, "\xEF\xBB\xBF") == 0) mLine.erase(0, 3); // BOM
        std::string_view view(mLine);
        size_t first = view.find_first_not_of(" \t");
        if (first == std::string_view::npos || view[first] == '#') continue;
        splitCsv(view, fields);
        mHeaderLine = mLineNo;
        std::set<std::string> seen;
        for (size_t i = 0; i < fields.size(); ++i) {
            std::string_view name = fields[i].text;
            if (name.size() >= 2 && name.front() == '"' && name.back() == '"')
                name = name.substr(1, name.size() - 2);
            if (name.empty())
                return dataError(mName, mLineNo, fields[i].col,
                                 "empty column name (column " + std::to_string(i + 1) + ")");
            double dummy;
            if (parseNumber(name, dummy).empty())
                return dataError(mName, mLineNo, fields[i].col,
                                 "the first line must be a header naming the columns "
                                 "(like x,y,z), found the number '" +
                                     std::string(name) + "'");
            if (!seen.insert(std::string(name)).second)
                return dataError(mName, mLineNo, fields[i].col,
                                 "duplicate column name '" + std::string(name) + "'");
            out.names.emplace_back(name);
        }
        out.columns.resize(out.names.size());
        mNames = out.names;
        return {};
    }
    if (mIn.bad()) return ioError(mName, "read failed: " + errnoText(errno));
    return dataError(mName, 0, 0,
                     "no header line: a CSV point file starts with the column names, e.g. x,y,z");
}

IoError CsvPointReader::readRows(PointSet& chunk, size_t maxRows) {
    chunk.names = mNames;
    chunk.columns.resize(mNames.size());
    chunk.float32.clear();
    for (std::vector<double>& column : chunk.columns) column.clear();
    std::vector<Field> fields;
    size_t rows = 0;
    while (rows < maxRows && std::getline(mIn, mLine)) {
        ++mLineNo;
        if (!mLine.empty() && mLine.back() == '\r') mLine.pop_back();
        std::string_view view(mLine);
        size_t first = view.find_first_not_of(" \t");
        if (first == std::string_view::npos || view[first] == '#') continue;
        splitCsv(view, fields);
        if (fields.size() != mNames.size())
            return dataError(mName, mLineNo, 1,
                             "row has " + std::to_string(fields.size()) + " field" +
                                 (fields.size() == 1 ? "" : "s") + ", header (line " +
                                 std::to_string(mHeaderLine) + ") has " +
                                 std::to_string(mNames.size()));
        for (size_t i = 0; i < fields.size(); ++i) {
            double v = 0.0;
            std::string msg = parseNumber(fields[i].text, v);
            if (!msg.empty()) return dataError(mName, mLineNo, fields[i].col, msg);
            chunk.columns[i].push_back(v);
        }
        ++rows;
    }
    if (mIn.bad()) return ioError(mName, "read failed: " + errnoText(errno));
    return {};
}

IoError readPointsCsv(std::istream& in, const std::string& displayName, PointSet& out) {
    CsvPointReader reader(in, displayName);
    if (IoError e = reader.readHeader(out)) return e;
    return reader.readRows(out, SIZE_MAX);
}

// ---- OBJ ----

namespace {
// tinyobjloader reads a coordinate it cannot parse ("abc", "1,5", "nan") as 0, a missing one as 0
// too, and one beyond single precision (its real_t) as ∞: a mesh would silently collapse or
// blow up. Every `v` line is checked here first: x, y and z present, numbers, finite, within
// float range; the first bad one is an error at its line and column.
IoError checkObjVertices(const std::string& path, std::istream& in) {
    std::string line;
    int lineNo = 0;
    while (std::getline(in, line)) {
        ++lineNo;
        size_t p = line.find_first_not_of(" \t");
        if (p == std::string::npos || line[p] != 'v' || p + 1 >= line.size() ||
            (line[p + 1] != ' ' && line[p + 1] != '\t'))
            continue;
        p += 1;
        for (int k = 0; k < 3; ++k) {
            p = line.find_first_not_of(" \t\r", p);
            if (p == std::string::npos || line[p] == '#')
                return dataError(path, lineNo, static_cast<int>(std::min(p, line.size()) + 1),
                                 "a vertex needs x, y and z, this one has " + std::to_string(k) +
                                     ": fix its v line");
            const size_t end = std::min(line.find_first_of(" \t\r", p), line.size());
            const std::string_view token(line.data() + p, end - p);
            double v = 0.0;
            std::string bad = parseNumber(token, v);
            if (bad.empty() && !std::isfinite(v))
                bad = "a vertex coordinate must be finite, not '" + std::string(token) + "'";
            else if (bad.empty() && std::abs(v) > std::numeric_limits<float>::max())
                bad = "'" + std::string(token) +
                      "' is beyond single precision (OBJ vertices are read as floats)";
            if (!bad.empty())
                return dataError(path, lineNo, static_cast<int>(p + 1),
                                 "vertex " + std::string(1, "xyz"[k]) + ": " + bad);
            p = end;
        }
    }
    if (in.bad()) return ioError(path, "read failed: " + errnoText(errno));
    return {};
}
} // namespace

IoError readPointsObj(const std::string& path, PointSet& out) {
    out = PointSet{};
    {
        errno = 0;
        std::ifstream probe(path);
        if (!probe) return ioError(path, "cannot open: " + errnoText(errno));
        if (IoError e = checkObjVertices(path, probe)) return e;
    }
    tinyobj::ObjReaderConfig config;
    config.triangulate = false;
    config.vertex_color = false;
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(path, config)) {
        std::string msg = reader.Error();
        while (!msg.empty() && (msg.back() == '\n' || msg.back() == '\r')) msg.pop_back();
        return dataError(path, 0, 0, "cannot parse OBJ: " + (msg.empty() ? "unknown error" : msg));
    }
    const tinyobj::attrib_t& attrib = reader.GetAttrib();
    size_t n = attrib.vertices.size() / 3;
    out.names = {"x", "y", "z"};
    out.columns.assign(3, std::vector<double>(n));
    out.float32.assign(3, std::is_same_v<tinyobj::real_t, float>); // the loader parses floats
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) out.columns[k][i] = attrib.vertices[3 * i + k];
    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
        size_t at = 0;
        for (unsigned char count : shape.mesh.num_face_vertices) {
            std::vector<int> face;
            face.reserve(count);
            for (unsigned j = 0; j < count && at < shape.mesh.indices.size(); ++j, ++at)
                face.push_back(shape.mesh.indices[at].vertex_index);
            // As the PLY reader: a face may only name vertices that exist (else every writer
            // would write a file that no reader accepts).
            for (int v : face)
                if (v < 0 || static_cast<size_t>(v) >= n)
                    return dataError(path, 0, 0,
                                     "face " + std::to_string(out.faces.size() + 1) +
                                         " refers to vertex " +
                                         std::to_string(static_cast<long long>(v) + 1) +
                                         " (counting from 1), but there are " + std::to_string(n) +
                                         " vertices: fix its f line");
            out.faces.push_back(std::move(face));
        }
    }
    return {};
}

// ---- writers ----

namespace {

IoError writeCsv(std::ostream& out, const PointSet& ps, bool header = true) {
    std::string buf;
    for (size_t c = 0; header && c < ps.names.size(); ++c) {
        if (c) buf += ',';
        buf += ps.names[c];
    }
    if (header) buf += '\n';
    size_t n = ps.size();
    for (size_t i = 0; i < n; ++i) {
        for (size_t c = 0; c < ps.columns.size(); ++c) {
            if (c) buf += ',';
            detail::appendNumber(buf, ps.columns[c][i], ps.isFloat32(static_cast<int>(c)));
        }
        buf += '\n';
        if (buf.size() > (1u << 16)) {
            out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
            buf.clear();
        }
    }
    out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
    return {};
}

IoError writeJson(std::ostream& out, const PointSet& ps) {
    std::vector<std::string> keys;
    for (const std::string& name : ps.names) {
        std::string k;
        k += jsonString(name);
        keys.push_back(k + ": ");
    }
    size_t n = ps.size();
    std::string buf = n ? "[\n" : "[";
    for (size_t i = 0; i < n; ++i) {
        buf += "  {";
        for (size_t c = 0; c < ps.columns.size(); ++c) {
            if (c) buf += ", ";
            buf += keys[c];
            double v = ps.columns[c][i];
            if (std::isfinite(v))
                detail::appendNumber(buf, v, ps.isFloat32(static_cast<int>(c)));
            else
                buf += "null";
        }
        buf += i + 1 < n ? "},\n" : "}\n";
        if (buf.size() > (1u << 16)) {
            out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
            buf.clear();
        }
    }
    buf += "]\n";
    out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
    return {};
}

void appendFloatLE(std::string& out, float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    char b[4] = {static_cast<char>(u & 0xff), static_cast<char>((u >> 8) & 0xff),
                 static_cast<char>((u >> 16) & 0xff), static_cast<char>((u >> 24) & 0xff)};
    out.append(b, 4);
}

IoError writeNpy(std::ostream& out, const PointSet& ps, const std::vector<int>& npyColumns) {
    std::vector<int> cols = npyColumns;
    if (cols.empty())
        for (size_t c = 0; c < ps.columns.size(); ++c) cols.push_back(static_cast<int>(c));
    for (int c : cols)
        if (c < 0 || static_cast<size_t>(c) >= ps.columns.size())
            return dataError("", 0, 0, "npy column " + std::to_string(c) + " does not exist");
    size_t n = ps.size();
    std::string shape = cols.size() == 1
                            ? "(" + std::to_string(n) + ",)"
                            : "(" + std::to_string(n) + ", " + std::to_string(cols.size()) + ")";
    std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': " + shape + ", }";
    // Magic (6) + version (2) + length (2) + header, padded with spaces so the data starts at
    // a multiple of 64 bytes, and ended by '\n'.
    size_t total = 10 + header.size() + 1;
    header.append((64 - total % 64) % 64, ' ');
    header += '\n';
    std::string buf("\x93NUMPY\x01\x00", 8);
    buf += static_cast<char>(header.size() & 0xff);
    buf += static_cast<char>((header.size() >> 8) & 0xff);
    buf += header;
    for (size_t i = 0; i < n; ++i) {
        for (int c : cols) appendFloatLE(buf, static_cast<float>(ps.columns[c][i]));
        if (buf.size() > (1u << 16)) {
            out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
            buf.clear();
        }
    }
    out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
    return {};
}

IoError writeObj(std::ostream& out, const PointSet& ps) {
    int x = ps.find("x"), y = ps.find("y"), z = ps.find("z");
    if (x < 0 || y < 0 || z < 0) return dataError("", 0, 0, "an OBJ file needs x, y and z columns");
    std::string buf = "# written by gale\n";
    size_t n = ps.size();
    for (size_t i = 0; i < n; ++i) {
        buf += "v ";
        detail::appendNumber(buf, ps.columns[x][i], ps.isFloat32(x));
        buf += ' ';
        detail::appendNumber(buf, ps.columns[y][i], ps.isFloat32(y));
        buf += ' ';
        detail::appendNumber(buf, ps.columns[z][i], ps.isFloat32(z));
        buf += '\n';
    }
    for (const std::vector<int>& face : ps.faces) {
        buf += 'f';
        for (int v : face) buf += ' ' + std::to_string(v + 1);
        buf += '\n';
    }
    out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
    return {};
}

} // namespace

IoError writePoints(std::ostream& out, const PointSet& points, PointFormat format,
                    const std::vector<int>& npyColumns) {
    IoError e;
    switch (format) {
    case PointFormat::Csv:
        e = writeCsv(out, points);
        break;
    case PointFormat::Ply:
        e = detail::writePly(out, points, true);
        break;
    case PointFormat::PlyAscii:
        e = detail::writePly(out, points, false);
        break;
    case PointFormat::Obj:
        e = writeObj(out, points);
        break;
    case PointFormat::Json:
        e = writeJson(out, points);
        break;
    case PointFormat::Npy:
        e = writeNpy(out, points, npyColumns);
        break;
    }
    if (e) return e;
    if (!out) return ioError("", "write failed: " + errnoText(errno));
    return {};
}

IoError writePointsCsv(std::ostream& out, const PointSet& points, bool header) {
    writeCsv(out, points, header);
    if (!out) return ioError("", "write failed: " + errnoText(errno));
    return {};
}

IoError writePointsFile(const std::string& path, const PointSet& points, PointFormat format,
                        const std::vector<int>& npyColumns) {
    return writeFileAtomic(path, [&](const std::string& tmp) -> IoError {
        errno = 0;
        std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
        if (!f) return ioErrorAt(path, "cannot write", errno);
        IoError e = writePoints(f, points, format, npyColumns);
        if (e) return e;
        f.flush();
        const int err = errno;
        f.close();
        if (f.fail()) return ioErrorAt(path, "cannot write", err);
        return {};
    });
}

// ---- host variables ----

static std::string variableName(const std::string& column) {
    std::string s = column;
    for (char& c : s) {
        unsigned char u = static_cast<unsigned char>(c);
        if (!(std::isalnum(u) || c == '_' || c == '.') || u >= 0x80) c = '_';
    }
    if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) s = "_" + s;
    return s;
}

std::vector<PointVariable> pointVariables(const PointSet& points) {
    std::vector<PointVariable> vars;
    std::set<std::string> used;
    std::vector<bool> consumed(points.names.size(), false);
    auto addVector = [&](const char* name, const char* a, const char* b, const char* c) {
        int ia = points.find(a), ib = points.find(b), ic = points.find(c);
        if (ia < 0 || ib < 0 || ic < 0) return;
        vars.push_back({name, {ia, ib, ic}});
        used.insert(name);
        consumed[ia] = consumed[ib] = consumed[ic] = true;
    };
    addVector("P", "x", "y", "z");
    addVector("N", "nx", "ny", "nz");
    for (size_t c = 0; c < points.names.size(); ++c) {
        if (consumed[c]) continue;
        std::string name = variableName(points.names[c]);
        if (!used.insert(name).second) continue;
        vars.push_back({name, {static_cast<int>(c)}});
    }
    return vars;
}

// A JSON string literal, quotes included, with control characters escaped.
std::string jsonString(const std::string& s) {
    std::string out;
    out += '"';
    for (unsigned char ch : s) {
        switch (ch) {
        case '"':
            out += "\\\"";
            break;
        case '\\':
            out += "\\\\";
            break;
        case '\n':
            out += "\\n";
            break;
        case '\t':
            out += "\\t";
            break;
        case '\r':
            out += "\\r";
            break;
        default:
            if (ch < 0x20) {
                char esc[8];
                std::snprintf(esc, sizeof esc, "\\u%04x", ch);
                out += esc;
            } else {
                out += static_cast<char>(ch);
            }
        }
    }
    out += '"';
    return out;
}

} // namespace gale::io
