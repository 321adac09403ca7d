#pragma once
// Files a run leaves in its output folder; each is complete or absent, never half-written.

#include <cstdio>
#include <filesystem>
#include <string>

namespace rend {

/// Writes `text` to path + ".tmp" and renames it into place.
void writeFileAtomic(const std::filesystem::path& path, const std::string& text);

/// stats.csv, one row per frame: appended to stats.csv.partial and flushed each frame, renamed
/// to stats.csv when the run ends (normally or by a blow-up).
class StatsWriter {
public:
    explicit StatsWriter(const std::filesystem::path& path);
    ~StatsWriter();
    StatsWriter(const StatsWriter&) = delete;
    StatsWriter& operator=(const StatsWriter&) = delete;

    struct Row {
        int frame;
        double time, kineticEnergy, strainEnergy, maxSpeed, maxTheta;
        std::size_t brokenBonds;
    };
    void append(const Row& row);
    void finish();

private:
    std::filesystem::path path_;
    std::FILE* file_ = nullptr;
};

/// Minimal JSON string escaping for run.json.
std::string jsonString(const std::string& text);

}  // namespace rend
