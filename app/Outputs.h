#pragma once
// Files a run leaves in its output folder; each is complete or absent, never half-written, and
// run.json's "files" lists exactly what the run wrote (see README "The command").

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "render/AtomicFile.h"
#include "render/RenderSettings.h"

namespace rend {

/// stats.csv, one row per frame: appended to stats.csv.partial with every write checked, renamed
/// to stats.csv by finish() (when the run ends normally or by a blow-up). A failed write throws
/// std::system_error naming the file and the reason and removes the partial file.
class StatsWriter {
public:
    explicit StatsWriter(const std::filesystem::path& path);
    ~StatsWriter();  ///< removes the partial file unless finish() ran
    StatsWriter(const StatsWriter&) = delete;
    StatsWriter& operator=(const StatsWriter&) = delete;

    struct Row {
        int frame;
        double time, kineticEnergy, strainEnergy, maxSpeed, maxTheta;
        std::size_t brokenBonds;
        long steps;  ///< explicit steps since t = 0
        double dt;   ///< the frame's last step [s]
    };
    void append(const Row& row);
    /// Rows carried over as text (a resumed run's earlier frames), each ending in a newline.
    void appendRows(const std::string& rows) {
        if (!rows.empty()) write(rows);
    }
    /// Renames stats.csv into place; false when a failed write already removed it.
    bool finish();

private:
    void write(const std::string& text);
    void discard();

    std::filesystem::path path_;
    std::optional<render::OutputFile> file_;
};

/// Whether `name` (relative to the output folder) is one rend writes: stats.csv,
/// frames/frame_N.{png,exr}, meshes/frame_N.{ply,obj,mtl,glb} or vdb/frame_N.vdb. Only such names
/// are ever removed, whatever a run.json lists.
bool isRunOutputName(const std::string& name);

/// The files the run.json in `outDir` lists under "files" that rend writes (isRunOutputName);
/// empty when there is no run.json or it lists none.
std::vector<std::string> previousRunFiles(const std::filesystem::path& outDir);

/// Removes the listed files and the temporary names a killed run may have left for them
/// (NAME.tmp, stats.csv.partial). Returns how many of the listed files existed.
int removeRunFiles(const std::filesystem::path& outDir, const std::vector<std::string>& names);

/// The output folder of one run and the files in it that rend wrote. A rerun overwrites frame by
/// frame, as Blender and Houdini do, and also removes what the previous run wrote there and this
/// run does not (previousRunFiles), so the folder always holds one run's files; files rend never
/// wrote are left alone. run.json lists previous + planned files while the run is going (a killed
/// run leaves them all listed for the next run to clean up) and exactly the written ones at the
/// end.
class RunFolder {
public:
    RunFolder(const std::filesystem::path& dir, std::vector<std::string> planned);

    /// What run.json lists while the run is going: the previous run's files and the planned ones.
    std::vector<std::string> listedWhileRunning() const;
    /// Removes the previous run's files that this run does not plan, and any temporary file a
    /// killed run left; returns the names of those that existed.
    std::vector<std::string> removeStale();
    void wrote(const std::vector<std::string>& names);
    /// Removes the previous run's files that this run planned but did not get to rewrite (it
    /// stopped early), so they are not taken for this run's; returns the files written, sorted.
    std::vector<std::string> finish();

private:
    std::filesystem::path dir_;
    std::vector<std::string> previous_, planned_, written_;
};

/// Minimal JSON string escaping for run.json.
std::string jsonString(const std::string& text);

/// A JSON array of strings, one per line at the given indent.
std::string jsonStringArray(const std::vector<std::string>& items, const std::string& indent);

/// The membrane's material as the renderers resolve it, the look's preset under the scene's own
/// keys: {"look", "material", "albedo", "roughness", "transmission"}. run.json carries it as
/// "shading", so scripts/blender_import.py gives Cycles the same material (the resolved scene
/// has only the keys the file wrote, not the look's defaults).
std::string shadingJson(const render::RenderSettings& settings);

}  // namespace rend
