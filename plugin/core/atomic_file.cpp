#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <unistd.h>

namespace fs = std::filesystem;

namespace vfield {

namespace {

std::string temporaryNameFor(const fs::path& path)
{
    // Process id and a counter keep concurrent writers (threads or processes) apart.
    static std::atomic<unsigned> counter{0};
    const std::string tag = ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    return (path.parent_path() / (path.stem().string() + tag + path.extension().string())).string();
}

} // namespace

void writeFileAtomically(const std::string& path, const std::function<void(const std::string&)>& write)
{
    const fs::path target(path);
    std::error_code ec;
    if (target.has_parent_path()) {
        fs::create_directories(target.parent_path(), ec);
        if (ec) throw FileError(path, "cannot create folder " + target.parent_path().string() + ": " + ec.message());
    }
    const std::string temporary = temporaryNameFor(target);
    try {
        write(temporary);
    } catch (...) {
        fs::remove(temporary, ec);
        throw;
    }
    if (!fs::exists(temporary, ec)) throw FileError(path, "the writer produced no file");
    fs::rename(temporary, target, ec);
    if (ec) {
        fs::remove(temporary, ec);
        throw FileError(path, "cannot move the finished file into place: " + ec.message());
    }
}

void writeTextAtomically(const std::string& path, const std::string& text)
{
    writeFileAtomically(path, [&](const std::string& temporary) {
        std::ofstream out(temporary, std::ios::binary);
        out << text;
        out.close();
        if (!out) throw FileError(path, "cannot write");
    });
}

std::string readFileBytes(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path, fs::exists(path) ? "cannot open for reading" : "no such file");
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

} // namespace vfield
