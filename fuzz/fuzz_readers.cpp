// libFuzzer harness for the point and mesh readers. The first byte picks the reader (mod 6):
// 0 CSV, 1 PLY (from memory), 2 OBJ point set, 3 OBJ mesh, 4 PLY mesh, 5 CSV strands (through a
// temp file); the rest is the file. A point set read must be consistent and survive a PLY
// round trip with the same shape; a mesh's triangles must index its vertices.
#include "io/pointset.h"
#include "solver/bodies/hair.h"
#include "solver/mesh/mesh.h"

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

using namespace gale;

namespace {

const std::string& workDir() {
    static const std::string dir = [] {
        const char* base = std::getenv("TMPDIR");
        std::string root = base && *base ? base : std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp";
        std::string d = root + "/gale-fuzz-readers-" + std::to_string(getpid());
        std::filesystem::create_directories(d);
        return d;
    }();
    return dir;
}

std::string writeTemp(const std::string& name, const std::string& bytes) {
    const std::string path = workDir() + "/" + name;
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return path;
}

void checkPoints(const io::PointSet& ps) {
    if (ps.names.size() != ps.columns.size()) __builtin_trap();
    for (const auto& c : ps.columns)
        if (c.size() != ps.size()) __builtin_trap();
    if (ps.columns.empty() || ps.size() > 100000) return;
    // Written as binary PLY and read back: the same number of points and columns.
    std::stringstream ply;
    if (io::writePoints(ply, ps, io::PointFormat::Ply)) return;
    io::PointSet back;
    if (io::IoError e = io::readPointsPly(ply, "roundtrip.ply", back)) __builtin_trap();
    if (back.size() != ps.size() || back.columns.size() != ps.columns.size()) __builtin_trap();
}

void checkMesh(const solver::TriMesh& m) {
    const int n = static_cast<int>(m.vertexCount());
    for (const auto& t : m.triangles)
        for (int v : t)
            if (v < 0 || v >= n) __builtin_trap();
    if (m.triangles.size() < 100000) {
        (void)solver::meshEdges(m.triangles);
        (void)solver::meshHinges(m.triangles);
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 1 || size > 1 << 20) return 0;
    const std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
    io::PointSet ps;
    std::string error;
    switch (data[0] % 6) {
    case 0: {
        std::istringstream in(bytes);
        if (!io::readPointsCsv(in, "fuzz.csv", ps)) checkPoints(ps);
        break;
    }
    case 1: {
        std::istringstream in(bytes);
        if (!io::readPointsPly(in, "fuzz.ply", ps)) checkPoints(ps);
        break;
    }
    case 2:
        if (!io::readPointsObj(writeTemp("points.obj", bytes), ps)) checkPoints(ps);
        break;
    case 3:
    case 4: {
        solver::TriMesh mesh;
        int dropped = 0;
        if (solver::loadMesh(writeTemp(data[0] % 6 == 3 ? "mesh.obj" : "mesh.ply", bytes), mesh, error, &dropped))
            checkMesh(mesh);
        else if (error.empty())
            __builtin_trap(); // a failure must say why
        break;
    }
    default: {
        solver::Strands strands;
        if (!solver::loadStrands(writeTemp("strands.csv", bytes), strands, error) && error.empty()) __builtin_trap();
        break;
    }
    }
    return 0;
}
