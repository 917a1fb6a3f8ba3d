// Test support shared by the io/, geometry/ and fields/ unit tests: a private temporary folder,
// removed with everything in it when the test ends.
#pragma once

#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <unistd.h>

namespace gale::io::test {

class TempDir {
public:
    // A new folder under the (canonical) temporary directory, unique per process and object.
    TempDir() {
        static std::atomic<int> counter{0};
        path = std::filesystem::canonical(std::filesystem::temp_directory_path()) /
               ("gale_fields_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
        std::filesystem::create_directories(path);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    std::string file(const std::string& name) const { return (path / name).string(); }
    // Writes `text` to `name` (creating its folders); returns the file's path.
    std::string write(const std::string& name, const std::string& text) const {
        const std::filesystem::path p = path / name;
        std::filesystem::create_directories(p.parent_path());
        std::ofstream(p, std::ios::binary) << text;
        return p.string();
    }

    std::filesystem::path path;
};

} // namespace gale::io::test
