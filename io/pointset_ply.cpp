// PLY point sets: a reader for ascii and binary (little/big-endian) files with arbitrary vertex
// properties, a kept face element and skipped other elements; a writer (binary little-endian
// or ascii) that stores every column as a float property, plus the faces.
#include "io/pointset.h"
#include "io/pointset_detail.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <istream>
#include <ostream>
#include <set>
#include <string_view>

namespace gale::io {

using detail::dataError;
using detail::ioError;

namespace {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

bool plyTypeFromName(std::string_view s, PlyType& t) {
    if (s == "char" || s == "int8")
        t = PlyType::Int8;
    else if (s == "uchar" || s == "uint8")
        t = PlyType::UInt8;
    else if (s == "short" || s == "int16")
        t = PlyType::Int16;
    else if (s == "ushort" || s == "uint16")
        t = PlyType::UInt16;
    else if (s == "int" || s == "int32")
        t = PlyType::Int32;
    else if (s == "uint" || s == "uint32")
        t = PlyType::UInt32;
    else if (s == "float" || s == "float32")
        t = PlyType::Float32;
    else if (s == "double" || s == "float64")
        t = PlyType::Float64;
    else
        return false;
    return true;
}

size_t plyTypeSize(PlyType t) {
    switch (t) {
    case PlyType::Int8:
    case PlyType::UInt8:
        return 1;
    case PlyType::Int16:
    case PlyType::UInt16:
        return 2;
    case PlyType::Int32:
    case PlyType::UInt32:
    case PlyType::Float32:
        return 4;
    case PlyType::Float64:
        return 8;
    }
    return 1;
}

bool plyTypeIsInteger(PlyType t) {
    return t != PlyType::Float32 && t != PlyType::Float64;
}

struct PlyProperty {
    std::string name;
    PlyType type = PlyType::Float32;
    bool isList = false;
    PlyType countType = PlyType::UInt8;
    int column = -1;          // vertex: destination column
    bool faceIndices = false; // face: the vertex_indices list
};

struct PlyElement {
    std::string name;
    size_t count = 0;
    int line = 0;
    std::vector<PlyProperty> props;
};

enum class PlyEncoding { Ascii, BinaryLE, BinaryBE };

std::vector<std::string_view> splitWords(std::string_view s) {
    std::vector<std::string_view> words;
    size_t i = 0;
    while (i < s.size()) {
        while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
        size_t j = i;
        while (j < s.size() && s[j] != ' ' && s[j] != '\t') ++j;
        if (j > i) words.push_back(s.substr(i, j - i));
        i = j;
    }
    return words;
}

bool hostIsLittleEndian() {
    uint16_t one = 1;
    unsigned char b;
    std::memcpy(&b, &one, 1);
    return b == 1;
}

// Reads the body (everything after end_header) one value at a time, ascii or binary.
class PlyBodyReader {
public:
    PlyBodyReader(std::string data, PlyEncoding enc, int firstLine)
        : mData(std::move(data)), mEncoding(enc), mLine(firstLine),
          mSwap(enc != PlyEncoding::Ascii &&
                (enc == PlyEncoding::BinaryLE) != hostIsLittleEndian()) {}

    // false at end of data (ascii: also on a malformed token, with `mBadToken` set).
    bool read(PlyType t, double& v) {
        return mEncoding == PlyEncoding::Ascii ? readAscii(t, v) : readBinary(t, v);
    }
    bool ascii() const { return mEncoding == PlyEncoding::Ascii; }
    int line() const { return mLine; }
    int col() const { return mTokenCol; }
    const std::string& badToken() const { return mBadToken; }
    size_t remaining() const { return mData.size() - mPos; }

private:
    bool readBinary(PlyType t, double& v) {
        size_t n = plyTypeSize(t);
        if (mData.size() - mPos < n) return false;
        unsigned char b[8];
        std::memcpy(b, mData.data() + mPos, n);
        mPos += n;
        if (mSwap)
            for (size_t i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
        switch (t) {
        case PlyType::Int8: {
            int8_t x;
            std::memcpy(&x, b, 1);
            v = x;
            break;
        }
        case PlyType::UInt8:
            v = b[0];
            break;
        case PlyType::Int16: {
            int16_t x;
            std::memcpy(&x, b, 2);
            v = x;
            break;
        }
        case PlyType::UInt16: {
            uint16_t x;
            std::memcpy(&x, b, 2);
            v = x;
            break;
        }
        case PlyType::Int32: {
            int32_t x;
            std::memcpy(&x, b, 4);
            v = x;
            break;
        }
        case PlyType::UInt32: {
            uint32_t x;
            std::memcpy(&x, b, 4);
            v = x;
            break;
        }
        case PlyType::Float32: {
            float x;
            std::memcpy(&x, b, 4);
            v = x;
            break;
        }
        case PlyType::Float64:
            std::memcpy(&v, b, 8);
            break;
        }
        return true;
    }

    bool readAscii(PlyType t, double& v) {
        // Skip whitespace, counting lines.
        while (mPos < mData.size()) {
            char c = mData[mPos];
            if (c == '\n') {
                ++mLine;
                mLineStart = mPos + 1;
            } else if (c != ' ' && c != '\t' && c != '\r') {
                break;
            }
            ++mPos;
        }
        if (mPos >= mData.size()) return false;
        size_t start = mPos;
        while (mPos < mData.size() && !std::isspace(static_cast<unsigned char>(mData[mPos])))
            ++mPos;
        mTokenCol = static_cast<int>(start - mLineStart + 1);
        const char* a = mData.data() + start;
        const char* e = mData.data() + mPos;
        if (*a == '+' && e - a > 1) ++a;
        std::from_chars_result r = std::from_chars(a, e, v);
        if (r.ec != std::errc() || r.ptr != e) {
            mBadToken.assign(mData.data() + start, static_cast<size_t>(e - (mData.data() + start)));
            return false;
        }
        if (t == PlyType::Float32) v = static_cast<float>(v);
        return true;
    }

    std::string mData;
    size_t mPos = 0;
    PlyEncoding mEncoding;
    int mLine;
    size_t mLineStart = 0;
    int mTokenCol = 0;
    bool mSwap;
    std::string mBadToken;
};

} // namespace

IoError readPointsPly(std::istream& in, const std::string& name, PointSet& out) {
    out = PointSet{};
    std::string line;
    int lineNo = 0;
    auto nextLine = [&]() -> bool {
        if (!std::getline(in, line)) return false;
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        return true;
    };
    if (!nextLine() || line != "ply")
        return dataError(name, 1, 1, "not a PLY file: the first line must be 'ply'");

    bool haveFormat = false, ended = false;
    PlyEncoding encoding = PlyEncoding::Ascii;
    std::vector<PlyElement> elements;
    while (nextLine()) {
        std::vector<std::string_view> w = splitWords(line);
        if (w.empty()) continue;
        std::string_view key = w[0];
        if (key == "comment" || key == "obj_info") continue;
        if (key == "end_header") {
            ended = true;
            break;
        }
        if (key == "format") {
            if (w.size() != 3)
                return dataError(name, lineNo, 1,
                                 "expected 'format <ascii|binary_little_endian|"
                                 "binary_big_endian> 1.0'");
            if (w[1] == "ascii")
                encoding = PlyEncoding::Ascii;
            else if (w[1] == "binary_little_endian")
                encoding = PlyEncoding::BinaryLE;
            else if (w[1] == "binary_big_endian")
                encoding = PlyEncoding::BinaryBE;
            else
                return dataError(name, lineNo, 8,
                                 "unknown PLY format '" + std::string(w[1]) +
                                     "': expected ascii, binary_little_endian "
                                     "or binary_big_endian");
            if (w[2] != "1.0" && w[2] != "1")
                return dataError(name, lineNo, 1,
                                 "unsupported PLY version '" + std::string(w[2]) +
                                     "' (only 1.0 is supported)");
            haveFormat = true;
        } else if (key == "element") {
            unsigned long long count = 0;
            if (w.size() != 3)
                return dataError(name, lineNo, 1, "expected 'element <name> <count>'");
            std::from_chars_result r =
                std::from_chars(w[2].data(), w[2].data() + w[2].size(), count);
            if (r.ec != std::errc() || r.ptr != w[2].data() + w[2].size())
                return dataError(name, lineNo, 1,
                                 "element count must be a non-negative integer, found '" +
                                     std::string(w[2]) + "'");
            for (const PlyElement& e : elements)
                if (e.name == w[1])
                    return dataError(name, lineNo, 1,
                                     "element '" + std::string(w[1]) +
                                         "' is declared twice (first on line " +
                                         std::to_string(e.line) + ")");
            PlyElement e;
            e.name = std::string(w[1]);
            e.count = static_cast<size_t>(count);
            e.line = lineNo;
            elements.push_back(std::move(e));
        } else if (key == "property") {
            if (elements.empty())
                return dataError(name, lineNo, 1, "'property' before any 'element'");
            PlyProperty p;
            size_t typeAt = 1;
            if (w.size() >= 2 && w[1] == "list") {
                if (w.size() != 5)
                    return dataError(name, lineNo, 1,
                                     "expected 'property list <count type> <item type> <name>'");
                p.isList = true;
                if (!plyTypeFromName(w[2], p.countType) || !plyTypeIsInteger(p.countType))
                    return dataError(name, lineNo, 1,
                                     "bad list count type '" + std::string(w[2]) +
                                         "': expected an integer type such as uchar");
                typeAt = 3;
            } else if (w.size() != 3) {
                return dataError(name, lineNo, 1, "expected 'property <type> <name>'");
            }
            if (!plyTypeFromName(w[typeAt], p.type))
                return dataError(name, lineNo, 1,
                                 "unknown property type '" + std::string(w[typeAt]) +
                                     "': expected char, uchar, short, ushort, int, uint, float, "
                                     "double (or int8 ... float64)");
            p.name = std::string(w[typeAt + 1]);
            for (const PlyProperty& q : elements.back().props)
                if (q.name == p.name)
                    return dataError(name, lineNo, 1,
                                     "property '" + p.name + "' of element '" +
                                         elements.back().name + "' is declared twice");
            elements.back().props.push_back(std::move(p));
        } else {
            return dataError(name, lineNo, 1,
                             "unknown PLY header line '" + std::string(key) +
                                 "': expected format, element, property, "
                                 "comment or end_header");
        }
    }
    if (in.bad()) return ioError(name, "read failed: " + std::string(std::strerror(errno)));
    if (!ended)
        return dataError(name, lineNo, 0,
                         "unexpected end of file in the PLY header: no 'end_header'");
    if (!haveFormat) return dataError(name, lineNo, 1, "the PLY header has no 'format' line");

    // Columns from the vertex element's scalar properties; the face element's index list.
    PlyElement* vertex = nullptr;
    for (PlyElement& e : elements) {
        if (e.name == "vertex") {
            vertex = &e;
            for (PlyProperty& p : e.props) {
                if (p.isList) continue; // per-vertex lists have no column form: skipped
                p.column = static_cast<int>(out.names.size());
                out.names.push_back(p.name);
                out.float32.push_back(p.type == PlyType::Float32);
            }
        } else if (e.name == "face") {
            for (PlyProperty& p : e.props)
                if (p.isList && (p.name == "vertex_indices" || p.name == "vertex_index")) {
                    p.faceIndices = true;
                    break;
                }
        }
    }
    if (!vertex) return dataError(name, lineNo, 0, "the PLY file has no 'vertex' element");
    size_t vertexCount = vertex->count;

    // The body: read it all, then walk the elements in order.
    std::string data;
    {
        char chunk[1 << 16];
        while (in.read(chunk, sizeof chunk) || in.gcount() > 0)
            data.append(chunk, static_cast<size_t>(in.gcount()));
        if (in.bad()) return ioError(name, "read failed: " + std::string(std::strerror(errno)));
    }
    PlyBodyReader body(std::move(data), encoding, lineNo + 1);
    out.plyBinary = encoding != PlyEncoding::Ascii;

    for (const PlyElement& e : elements) {
        // Sanity-check counts against the data size before allocating: every binary value
        // takes its size, every ascii value at least one character and a separator.
        if (!e.props.empty()) {
            size_t minSize = 0;
            for (const PlyProperty& p : e.props)
                minSize += body.ascii() ? 2
                           : p.isList   ? plyTypeSize(p.countType)
                                        : plyTypeSize(p.type);
            if (e.count > (body.remaining() + 1) / minSize)
                return dataError(
                    name, body.ascii() ? body.line() : 0, 0,
                    std::string(body.ascii() ? "unexpected end of file" : "truncated binary data") +
                        ": the header (line " + std::to_string(e.line) + ") declares " +
                        std::to_string(e.count) + " " + e.name +
                        " elements, more than the file holds");
        }
        bool isVertex = &e == vertex;
        // (Columns only for properties: a vertex element without any holds no data, and its
        // count, checked against the file only when it has properties, may be anything.)
        if (isVertex)
            out.columns.assign(out.names.size(),
                               std::vector<double>(out.names.empty() ? 0 : e.count));
        // An element without properties holds no bytes, whatever its count says (a fuzzed
        // header declared 4.8e18 of them: walking them one by one never ended).
        if (e.props.empty()) continue;

        for (size_t i = 0; i < e.count; ++i) {
            for (const PlyProperty& p : e.props) {
                auto fail = [&]() {
                    std::string where =
                        e.name + " " + std::to_string(i) + " (property '" + p.name + "')";
                    if (body.ascii() && !body.badToken().empty())
                        return dataError(name, body.line(), body.col(),
                                         std::string("expected a number for ") + where +
                                             ", found '" + body.badToken() + "'");
                    if (body.ascii())
                        return dataError(name, body.line(), 0,
                                         "unexpected end of file in " + where +
                                             ": the header says " + std::to_string(e.count) + " " +
                                             e.name + " elements");
                    return dataError(name, 0, 0,
                                     std::string("truncated binary data: the file ends in ") +
                                         where + " of " + std::to_string(e.count) + " " + e.name +
                                         " elements");
                };
                double v = 0.0;
                if (!p.isList) {
                    if (!body.read(p.type, v)) return fail();
                    if (p.column >= 0) out.columns[p.column][i] = v;
                    continue;
                }
                if (!body.read(p.countType, v)) return fail();
                if (!(v >= 0) || v != std::floor(v) || v > 1e9)
                    return dataError(name, body.ascii() ? body.line() : 0,
                                     body.ascii() ? body.col() : 0,
                                     "bad list length " + formatNumber(v) + " in " + e.name + " " +
                                         std::to_string(i) + " (property '" + p.name + "')");
                size_t len = static_cast<size_t>(v);
                // As for the element counts: a list cannot hold more items than the bytes
                // left (a fuzzed length of 7e8 asked for 2.9 GB before the first item).
                const size_t itemSize = body.ascii() ? 2 : plyTypeSize(p.type);
                if (len > (body.remaining() + 1) / itemSize)
                    return dataError(name, body.ascii() ? body.line() : 0,
                                     body.ascii() ? body.col() : 0,
                                     "list length " + formatNumber(v) + " in " + e.name + " " +
                                         std::to_string(i) + " (property '" + p.name +
                                         "') is more than the file holds");
                std::vector<int> face;
                if (p.faceIndices) face.reserve(len);
                for (size_t k = 0; k < len; ++k) {
                    if (!body.read(p.type, v)) return fail();
                    if (!p.faceIndices) continue;
                    if (!(v >= 0) || v >= static_cast<double>(vertexCount) || v != std::floor(v))
                        return dataError(name, body.ascii() ? body.line() : 0,
                                         body.ascii() ? body.col() : 0,
                                         e.name + " " + std::to_string(i) + " refers to vertex " +
                                             formatNumber(v) + ", but there are " +
                                             std::to_string(vertexCount) + " vertices");
                    face.push_back(static_cast<int>(v));
                }
                if (p.faceIndices) out.faces.push_back(std::move(face));
            }
        }
    }
    return {};
}

// ---- writer ----

namespace detail {

namespace {

std::string plyName(const std::string& s) {
    if (s.empty()) return "unnamed";
    std::string r = s;
    for (char& c : r)
        if (static_cast<unsigned char>(c) <= ' ' || c == '\x7f') c = '_'; // spaces, controls, NUL
    return r;
}

// Property names for the columns: plyName, made unique ("a b" and "a_b" are "a_b", "a_b_2"),
// since a reader rejects a property declared twice.
std::vector<std::string> plyNames(const std::vector<std::string>& names) {
    std::vector<std::string> out;
    std::set<std::string> used;
    for (const std::string& s : names) {
        const std::string base = plyName(s);
        std::string name = base;
        for (int k = 2; !used.insert(name).second; ++k) name = base + "_" + std::to_string(k);
        out.push_back(name);
    }
    return out;
}

void appendLE(std::string& out, const void* p, size_t n) {
    const unsigned char* b = static_cast<const unsigned char*>(p);
    if (hostIsLittleEndian()) {
        out.append(reinterpret_cast<const char*>(b), n);
    } else {
        for (size_t i = n; i-- > 0;) out += static_cast<char>(b[i]);
    }
}

} // namespace

IoError writePly(std::ostream& out, const PointSet& ps, bool binary) {
    size_t n = ps.size();
    size_t maxFace = 0;
    for (const std::vector<int>& f : ps.faces) maxFace = std::max(maxFace, f.size());
    const char* countType = maxFace > 255 ? "uint" : "uchar";

    std::string buf = "ply\n";
    buf += binary ? "format binary_little_endian 1.0\n" : "format ascii 1.0\n";
    buf += "comment written by gale\n";
    buf += "element vertex " + std::to_string(n) + "\n";
    for (const std::string& name : plyNames(ps.names)) buf += "property float " + name + "\n";
    if (!ps.faces.empty()) {
        buf += "element face " + std::to_string(ps.faces.size()) + "\n";
        buf += std::string("property list ") + countType + " int vertex_indices\n";
    }
    buf += "end_header\n";

    auto flush = [&](bool force) {
        if (force || buf.size() > (1u << 16)) {
            out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
            buf.clear();
        }
    };
    for (size_t i = 0; i < n; ++i) {
        for (size_t c = 0; c < ps.columns.size(); ++c) {
            float f = static_cast<float>(ps.columns[c][i]);
            if (binary) {
                appendLE(buf, &f, 4);
            } else {
                if (c) buf += ' ';
                appendNumber(buf, f, true);
            }
        }
        if (!binary) buf += '\n';
        flush(false);
    }
    for (const std::vector<int>& face : ps.faces) {
        if (binary) {
            if (maxFace > 255) {
                uint32_t len = static_cast<uint32_t>(face.size());
                appendLE(buf, &len, 4);
            } else {
                buf += static_cast<char>(static_cast<unsigned char>(face.size()));
            }
            for (int v : face) {
                int32_t x = v;
                appendLE(buf, &x, 4);
            }
        } else {
            buf += std::to_string(face.size());
            for (int v : face) buf += ' ' + std::to_string(v);
            buf += '\n';
        }
        flush(false);
    }
    flush(true);
    return {};
}

} // namespace detail

} // namespace gale::io
