#pragma once
// Scratch folders for the C++ tests. ctest runs every test as a process of its own, two or more
// at a time, so a fixed path under the system temp folder is a race: one test reads a scene file
// while another rewrites it. Each test process gets its own folder, removed with its contents
// when the process exits.
#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace rtsim::test {

/// The folder `name` (created) inside this process's own temp folder.
inline std::filesystem::path process_temp_dir(const std::string& name) {
    struct Root {
        std::filesystem::path path =
            std::filesystem::temp_directory_path() / ("rtsim_test_" + std::to_string(::getpid()));
        ~Root() {
            std::error_code ignored;  // best effort: a leftover folder is not a test failure
            std::filesystem::remove_all(path, ignored);
        }
    };
    static const Root root;
    const std::filesystem::path dir = root.path / name;
    std::filesystem::create_directories(dir);
    return dir;
}

}  // namespace rtsim::test
