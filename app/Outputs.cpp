#include "app/Outputs.h"

#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "app/SceneReader.h"

namespace rend {

void writeFileAtomic(const std::filesystem::path& path, const std::string& text) {
    std::filesystem::path tmp = path;
    tmp += ".tmp";
    {
        std::ofstream out(tmp, std::ios::binary);
        out << text;
        if (!out) throw std::runtime_error("cannot write " + tmp.string());
    }
    std::filesystem::rename(tmp, path);
}

StatsWriter::StatsWriter(const std::filesystem::path& path) : path_(path) {
    std::filesystem::path partial = path_;
    partial += ".partial";
    file_ = std::fopen(partial.c_str(), "w");
    if (!file_) throw std::runtime_error("cannot write " + partial.string());
    std::fputs("frame,time,kinetic_energy,strain_energy,max_speed,max_theta,broken_bonds\n", file_);
}

StatsWriter::~StatsWriter() {
    if (file_) std::fclose(file_);
}

void StatsWriter::append(const Row& r) {
    std::fprintf(file_, "%d,%.9g,%.9g,%.9g,%.9g,%.9g,%zu\n", r.frame, r.time, r.kineticEnergy,
                 r.strainEnergy, r.maxSpeed, r.maxTheta, r.brokenBonds);
    std::fflush(file_);
}

void StatsWriter::finish() {
    if (!file_) return;
    std::fclose(file_);
    file_ = nullptr;
    std::filesystem::path partial = path_;
    partial += ".partial";
    std::filesystem::rename(partial, path_);
}

std::string jsonString(const std::string& text) {
    // TOML basic strings and JSON strings share their escapes (\", \\, \uXXXX).
    return scene::tomlString(text);
}

}  // namespace rend
