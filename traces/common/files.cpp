// Path checks before opening or writing (files.h).
#include "traces/common/files.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "traces/common/error.h"

namespace rtsim {

namespace fs = std::filesystem;

void require_regular_file(const std::string& path, const std::string& what) {
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    require(fs::exists(status), path + ": cannot open " + what + ": no such file");
    require(!fs::is_directory(status), path + ": is a folder, not a " + what);
    require(fs::is_regular_file(status),
            path + ": is not a regular file (a FIFO, device or socket); give a " + what);
}

void require_utf8_path(const std::string& path, const std::string& what) {
    const auto* s = reinterpret_cast<const unsigned char*>(path.data());
    const size_t n = path.size();
    for (size_t i = 0; i < n;) {
        const unsigned char c = s[i];
        const size_t len = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
        bool ok = len > 0 && i + len <= n && c != 0xC0 && c != 0xC1 && c <= 0xF4;
        for (size_t k = 1; ok && k < len; ++k) ok = (s[i + k] & 0xC0) == 0x80;
        if (!ok) {
            char hex[8];
            std::snprintf(hex, sizeof hex, "\\x%02x", c);
            std::string shown;
            for (unsigned char b : path) {
                char h[8];
                std::snprintf(h, sizeof h, "\\x%02x", b);
                shown += b < 0x80 ? std::string(1, char(b)) : std::string(h);
            }
            throw Error(what + " path '" + shown + "' is not valid UTF-8 (byte " + hex + " at " +
                        std::to_string(i) + "); rtsim records paths in JSON: rename the file or folder");
        }
        i += len;
    }
}

void make_output_folder(const std::string& path, const std::string& what) {
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    require(!fs::exists(status) || fs::is_directory(status),
            path + ": is a file, not a folder (the " + what + " folder); give a folder path");
    fs::create_directories(path, ec);
    require(!ec, path + ": cannot create the " + what + " folder (" + ec.message() + ")");
    // Writable? A probe file, removed at once: /proc and read-only mounts fail here, not later.
    const fs::path probe = fs::path(path) / ".rtsim-write-probe";
    {
        std::ofstream out(probe);
        require(bool(out), path + ": cannot write into the " + what + " folder");
    }
    fs::remove(probe, ec);
}

std::string read_small_file(const std::string& path, const std::string& what, uint64_t max_bytes) {
    require_regular_file(path, what);
    std::error_code ec;
    const uintmax_t size = fs::file_size(path, ec);
    require(!ec, path + ": cannot read (" + ec.message() + ")");
    require(size <= max_bytes, path + ": " + std::to_string(size) + " bytes; a " + what + " of more than " +
                                   std::to_string(max_bytes) + " bytes is refused");
    std::ifstream in(path, std::ios::binary);
    require(bool(in), path + ": cannot open the " + what);
    std::string text(static_cast<size_t>(size), '\0');
    in.read(text.data(), std::streamsize(size));
    require(bool(in) || in.eof(), path + ": cannot read the " + what);
    text.resize(static_cast<size_t>(in.gcount()));
    return text;
}

}  // namespace rtsim
