#pragma once
// Files in and out. Output that is never half-written: data goes to a temporary file beside the
// target and is renamed into place only once complete (rename is atomic within a file system).
// Input that is never read without bound (read_file_bounded).

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace lamina {

/// The whole content of the file at `path`, read as `what` (named in errors, e.g. "the stack
/// file"): InputError naming the path when it cannot be read (missing, a folder) or holds more
/// than max_bytes. A file that is not a regular one (a device such as /dev/zero, a pipe) is read
/// no further than 16 MiB, so that a stream without end is refused rather than read forever.
std::string read_file_bounded(const std::filesystem::path& path, std::size_t max_bytes,
                              std::string_view what);

/// read_file_bounded for a file lamina wrote itself (a study's files, a cache's entries): one that
/// is not a regular file (a pipe, whose opening would wait for a writer; a device) is refused
/// before it is opened: InputError naming the path.
std::string read_regular_file_bounded(const std::filesystem::path& path, std::size_t max_bytes,
                                      std::string_view what);

/// A cache entry's bytes: the content of the regular file at `path` if it holds at most
/// max_bytes; nothing otherwise (missing, a folder, a pipe or device — never opened —, larger,
/// unreadable): the caller recomputes the entry.
std::optional<std::string> read_cache_file(const std::filesystem::path& path,
                                           std::size_t max_bytes);

/// 2 GiB: the largest table (brdf.csv, a .bsdf tensor file) lamina reads.
inline constexpr std::size_t kMaxTableFileBytes = std::size_t(2) << 30;

/// Writes `content` to `path` atomically. Throws InputError naming the path on failure; the
/// temporary file is removed and any previous `path` is left untouched.
void write_file_atomic(const std::filesystem::path& path, std::string_view content);

/// write_file_atomic, except that a `path` already holding exactly `content` is left untouched
/// (content and modification time): a re-run that changes nothing rewrites nothing. Returns
/// whether it wrote.
bool write_file_if_changed(const std::filesystem::path& path, std::string_view content);

/// Whether `path` is a regular file holding exactly `content`.
bool file_holds(const std::filesystem::path& path, std::string_view content);

/// A set of files written together into one folder: every file is staged in a hidden temporary
/// folder inside the target, and `commit()` renames them all into place. If the object is destroyed
/// without commit (an error, an exception), nothing staged reaches the target folder, and a target
/// folder it created is removed again.
class StagedOutput {
  public:
    /// Creates `dir` if needed and checks it is writable; throws InputError otherwise, naming
    /// `field` (the option or argument that gave the folder).
    explicit StagedOutput(std::filesystem::path dir, std::string field = "--out");
    ~StagedOutput();
    StagedOutput(const StagedOutput&) = delete;
    StagedOutput& operator=(const StagedOutput&) = delete;

    /// Stages one file (name relative to the target folder).
    void add(const std::string& name, std::string_view content);
    /// Where to write the file `name` that a writer of its own writes to a path (a PNG or EXR
    /// library): a path in the staging folder, moved into place at commit as add()'s files.
    std::filesystem::path stage_path(const std::string& name);
    /// Stages it only if the target folder does not already hold exactly `content` under `name`
    /// (which then keeps its modification time). Returns whether it staged.
    bool add_if_changed(const std::string& name, std::string_view content);
    /// At commit, deletes `name` from the target folder unless this output stages it: a file
    /// that an earlier run of another kind wrote there (a spectral or Mueller table) and that
    /// would otherwise lie beside this run's files as if it were one of them.
    void remove_unless_staged(const std::string& name);
    /// Moves every staged file into the target folder (and deletes those remove_unless_staged
    /// named that it did not stage).
    void commit();

    const std::filesystem::path& dir() const { return dir_; }

  private:
    std::filesystem::path dir_, staging_;
    std::vector<std::string> names_, stale_;
    bool committed_ = false;
    std::vector<std::filesystem::path> created_;  // the folders the constructor made, deepest first
    int slot_ = -1;  // its place among the folders an interrupt removes
};

/// Installs handlers of SIGINT, SIGTERM and SIGHUP that remove the live StagedOutputs' staging
/// folders and the folders they created (the target and its parents, where empty) before the
/// signal's default action: an interrupted run leaves nothing behind either (the command line's;
/// Python handles Ctrl-C itself, between chunks of particles).
void remove_staging_on_interrupt();

/// A child process of the run (a Python model binning its table) for the same handler: on an
/// interrupt it is sent SIGTERM, and its temporary folder `dir`, holding at most the named files,
/// is removed. Returns a slot for unregister_interrupt_child, called once the child has ended
/// (−1 when no slot is free: then it is not ended on an interrupt).
int register_interrupt_child(int pid, const std::filesystem::path& dir,
                             const std::vector<std::string>& files);
void unregister_interrupt_child(int slot);

}  // namespace lamina
