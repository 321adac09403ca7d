#include "app/Outputs.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>
#include <system_error>

#include "app/SceneNames.h"
#include "app/SceneReader.h"

namespace rend {

namespace fs = std::filesystem;

StatsWriter::StatsWriter(const fs::path& path) : path_(path) {
    fs::path partial = path_;
    partial += ".partial";
    file_.emplace(partial);
    write("frame,time,kinetic_energy,strain_energy,max_speed,max_theta,broken_bonds,steps,dt\n");
}

StatsWriter::~StatsWriter() {
    if (file_) discard();
}

void StatsWriter::discard() {
    const fs::path partial = file_->path();
    file_.reset();
    std::error_code ignored;
    fs::remove(partial, ignored);
}

void StatsWriter::write(const std::string& text) {
    try {
        file_->write(text);
    } catch (...) {
        discard();
        throw;
    }
}

void StatsWriter::append(const Row& r) {
    char row[256];
    std::snprintf(row, sizeof row, "%d,%.9g,%.9g,%.9g,%.9g,%.9g,%zu,%ld,%.9g\n", r.frame, r.time,
                  r.kineticEnergy, r.strainEnergy, r.maxSpeed, r.maxTheta, r.brokenBonds, r.steps,
                  r.dt);
    write(row);
}

bool StatsWriter::finish() {
    if (!file_) return false;
    const fs::path partial = file_->path();
    std::error_code ec;
    try {
        file_->close();
        fs::rename(partial, path_, ec);
    } catch (const std::system_error& e) {
        ec = e.code();
    }
    file_.reset();
    if (!ec) return true;
    fs::remove(partial, ec);
    throw std::system_error(ec, "cannot write " + path_.string());
}

bool isRunOutputName(const std::string& name) {
    static const std::regex kNames(
        R"(stats\.csv|frames/frame_[0-9]{4,9}\.(png|exr)|meshes/frame_[0-9]{4,9}\.(ply|obj|mtl|glb)|)"
        R"(vdb/frame_[0-9]{4,9}\.vdb|cache/frame_[0-9]{4,9}\.rcache|cache/source\.toml)");
    return std::regex_match(name, kNames);
}

namespace {

// The strings of the array after "files": in run.json as rend writes it. Names rend writes need
// no escapes; one that has them splits wrongly and then fails isRunOutputName.
std::vector<std::string> filesArray(const std::string& json) {
    std::vector<std::string> names;
    std::size_t at = json.find("\"files\": [");
    if (at == std::string::npos) return names;
    const std::size_t end = json.find(']', at);
    if (end == std::string::npos) return names;
    for (at = json.find('"', at + 9); at < end; at = json.find('"', at + 1)) {
        const std::size_t close = json.find('"', at + 1);
        if (close > end) break;
        names.push_back(json.substr(at + 1, close - at - 1));
        at = close;
    }
    return names;
}

}  // namespace

std::vector<std::string> previousRunFiles(const fs::path& outDir) {
    std::ifstream in(outDir / "run.json", std::ios::binary);
    if (!in) return {};
    // run.json is a few kilobytes; a larger file is not one rend wrote.
    std::string json(1 << 22, '\0');
    in.read(json.data(), std::streamsize(json.size()));
    json.resize(std::size_t(in.gcount()));
    std::vector<std::string> names;
    for (std::string& name : filesArray(json))
        if (isRunOutputName(name)) names.push_back(std::move(name));
    return names;
}

int removeRunFiles(const fs::path& outDir, const std::vector<std::string>& names) {
    int removed = 0;
    std::error_code ignored;
    for (const std::string& name : names) {
        removed += fs::remove(outDir / name, ignored) ? 1 : 0;
        fs::remove(render::temporaryName(outDir / name), ignored);
        if (name.find('/') != std::string::npos)
            fs::remove((outDir / name).parent_path(), ignored);  // only when now empty
    }
    fs::remove(outDir / "stats.csv.partial", ignored);
    return removed;
}

namespace {

std::vector<std::string> sorted(std::vector<std::string> names) {
    std::sort(names.begin(), names.end());
    names.erase(std::unique(names.begin(), names.end()), names.end());
    return names;
}

// Names in `a` that are not in `b`; both sorted.
std::vector<std::string> minus(const std::vector<std::string>& a,
                               const std::vector<std::string>& b) {
    std::vector<std::string> out;
    std::set_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
    return out;
}

}  // namespace

RunFolder::RunFolder(const fs::path& dir, std::vector<std::string> planned)
    : dir_(dir), previous_(sorted(previousRunFiles(dir))), planned_(sorted(std::move(planned))) {}

std::vector<std::string> RunFolder::listedWhileRunning() const {
    std::vector<std::string> all = previous_;
    all.insert(all.end(), planned_.begin(), planned_.end());
    return sorted(std::move(all));
}

std::vector<std::string> RunFolder::removeStale() {
    std::vector<std::string> removed;
    for (const std::string& name : minus(previous_, planned_))
        if (fs::exists(dir_ / name)) removed.push_back(name);
    removeRunFiles(dir_, removed);
    // A killed run's temporary files; the files themselves stay until this run overwrites them.
    std::error_code ignored;
    for (const std::string& name : listedWhileRunning())
        fs::remove(render::temporaryName(dir_ / name), ignored);
    return removed;
}

void RunFolder::wrote(const std::vector<std::string>& names) {
    written_.insert(written_.end(), names.begin(), names.end());
}

std::vector<std::string> RunFolder::finish() {
    written_ = sorted(std::move(written_));
    std::vector<std::string> notReached;
    std::set_intersection(previous_.begin(), previous_.end(), planned_.begin(), planned_.end(),
                          std::back_inserter(notReached));
    removeRunFiles(dir_, minus(notReached, written_));
    return written_;
}

std::string jsonString(const std::string& text) {
    // TOML basic strings and JSON strings share their escapes (\", \\, \uXXXX).
    return scene::tomlString(text);
}

std::string jsonStringArray(const std::vector<std::string>& items, const std::string& indent) {
    if (items.empty()) return "[]";
    std::string out = "[";
    for (std::size_t k = 0; k < items.size(); ++k)
        out += (k ? ",\n" : "\n") + indent + "  " + jsonString(items[k]);
    return out + "\n" + indent + "]";
}

std::string shadingJson(const render::RenderSettings& settings) {
    const render::PathTracing& pt = settings.pathTracing;
    std::ostringstream j;
    j.precision(6);
    j << "{\"look\": " << jsonString(std::string(names::kLooks[std::size_t(settings.look)]))
      << ", \"material\": " << jsonString(std::string(names::kMaterials[std::size_t(pt.material)]))
      << ", \"albedo\": [" << settings.albedo.x() << ", " << settings.albedo.y() << ", "
      << settings.albedo.z() << "], \"roughness\": " << pt.roughness
      << ", \"transmission\": " << pt.transmission << "}";
    return j.str();
}

}  // namespace rend
