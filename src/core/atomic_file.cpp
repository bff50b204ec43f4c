#include "core/atomic_file.h"

#include "core/error.h"

#include <fmt/format.h>
#include <unistd.h>

#include <csignal>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <string_view>
#include <system_error>
#include <vector>

namespace fs = std::filesystem;

namespace lamina {

namespace {

// The staging folders of the live StagedOutputs, and the target folders they created, for the
// interrupt handler (remove_staging_on_interrupt): fixed slots of plain characters, as a signal
// handler may read them but not allocate. A slot is claimed (`used`), filled, then published
// (`ready`); the handler reads the published ones only, so it never sees a path half copied.
constexpr int kSlots = 16;
constexpr std::size_t kPathBytes = 4096;
struct Slot {
    std::atomic<bool> used{false};
    std::atomic<bool> ready{false};
    char staging[kPathBytes];
    char created[kPathBytes];  // the deepest folder the run made; empty: it made none
    int created_levels = 0;    // how many folders it made: `created` and its parents
};
Slot g_slots[kSlots];

int register_staging(const fs::path& staging, const fs::path& created, int created_levels) {
    const std::string a = staging.string(), b = created.string();
    if (a.size() >= kPathBytes || b.size() >= kPathBytes) return -1;
    for (int i = 0; i < kSlots; ++i) {
        bool expected = false;
        if (g_slots[i].used.load() || !g_slots[i].used.compare_exchange_strong(expected, true))
            continue;
        std::memcpy(g_slots[i].staging, a.c_str(), a.size() + 1);
        std::memcpy(g_slots[i].created, b.c_str(), b.size() + 1);
        g_slots[i].created_levels = created_levels;
        g_slots[i].ready.store(true);
        return i;
    }
    return -1;  // more than kSlots at once: not cleaned on an interrupt
}

// The child processes of a run (a Python model binning its table) and their temporary folders,
// for the interrupt handler: each is sent SIGTERM, and its folder's files and the folder removed
// (kill, unlink and rmdir: async-signal-safe). Published as the staging slots are.
constexpr int kChildSlots = 16;
constexpr int kChildFiles = 3;
struct ChildSlot {
    std::atomic<bool> used{false};
    std::atomic<bool> ready{false};
    pid_t pid = 0;
    char dir[kPathBytes];
    char files[kChildFiles][kPathBytes];
    int n_files = 0;
};
ChildSlot g_children[kChildSlots];

// An interrupt (SIGINT, SIGTERM, SIGHUP) while outputs are staged: the registered child processes
// are sent SIGTERM and their temporary files and folders removed; the staging folders are
// removed, and the folders the run created, deepest first, where empty (rmdir only:
// async-signal-safe; a staging folder is empty while the run computes, its files are written at
// the end); then the signal's default action.
extern "C" void remove_staging_and_reraise(int signal_number) {
    for (ChildSlot& child : g_children) {
        if (!child.ready.load()) continue;
        ::kill(child.pid, SIGTERM);
        for (int f = 0; f < child.n_files; ++f)
            ::unlink(child.files[f]);
        ::rmdir(child.dir);
    }
    for (Slot& slot : g_slots) {
        if (!slot.ready.load()) continue;
        ::rmdir(slot.staging);
        // Each parent is the path cut at its last '/' (the folders were recorded normalized).
        char path[kPathBytes];
        std::size_t length = 0;
        while (length + 1 < kPathBytes && slot.created[length] != '\0') {
            path[length] = slot.created[length];
            ++length;
        }
        path[length] = '\0';
        for (int level = 0; level < slot.created_levels && length > 0; ++level) {
            if (::rmdir(path) != 0) break;
            while (length > 0 && path[length - 1] != '/')
                --length;
            while (length > 0 && path[length - 1] == '/')
                --length;
            path[length] = '\0';
        }
    }
    ::signal(signal_number, SIG_DFL);
    ::raise(signal_number);
}

// The staging folders a killed run left in `dir` (SIGKILL: no handler runs): ".staging-PID.N"
// whose process no longer exists on this machine. A live run's folder, another process's of this
// machine, is never touched; a reused PID only keeps a dead folder a while longer.
void remove_dead_staging(const fs::path& dir) {
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        constexpr std::string_view kPrefix = ".staging-";
        if (!name.starts_with(kPrefix)) continue;
        long pid = 0;
        const char* first = name.data() + kPrefix.size();
        const auto [ptr, parse] = std::from_chars(first, name.data() + name.size(), pid);
        if (parse != std::errc() || ptr == first || *ptr != '.' || pid <= 0 || pid == ::getpid())
            continue;
        if (::kill(pid_t(pid), 0) != 0 && errno == ESRCH) {
            std::error_code ignored;
            fs::remove_all(it->path(), ignored);
        }
    }
}

std::string unique_suffix() {
    static std::atomic<unsigned> counter{0};
    return fmt::format("{}.{}", ::getpid(), counter++);
}

// Writes `path` (a temporary name) for the file `target`; errors name the target, the file the
// user asked for.
void write_all(const fs::path& path, const fs::path& target, std::string_view content) {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) {
        const int error = errno;
        std::error_code ec;
        const fs::path parent = target.parent_path().empty() ? "." : target.parent_path();
        throw InputError(target.string(), "",
                         !fs::is_directory(parent, ec)
                             ? fmt::format("cannot write it: {} is not a folder", parent.string())
                             : fmt::format("cannot write it: {}", std::strerror(error)));
    }
    const bool ok = std::fwrite(content.data(), 1, content.size(), f) == content.size();
    const bool flushed = std::fflush(f) == 0 && ::fsync(::fileno(f)) == 0;
    const bool closed = std::fclose(f) == 0;
    if (!ok || !flushed || !closed) {
        std::error_code ec;
        fs::remove(path, ec);
        throw InputError(target.string(), "", "write failed (disk full or not writable?)");
    }
}

}  // namespace

void write_file_atomic(const fs::path& path, std::string_view content) {
    // The finished file is renamed over `path`: a link, pipe or device there would be replaced by
    // it (a symbolic link's target left as it was, /dev/null made a file).
    std::error_code status_ec;
    const fs::file_status status = fs::symlink_status(path, status_ec);
    if (!status_ec && fs::exists(status) && !fs::is_regular_file(status) &&
        !fs::is_directory(status))
        throw InputError(path.string(), "",
                         "cannot write it: it is not a regular file (a link, pipe or device), "
                         "which the finished file would replace; allowed: a regular file or a new "
                         "name");
    const fs::path tmp =
        path.parent_path() / fmt::format(".{}.tmp-{}", path.filename().string(), unique_suffix());
    write_all(tmp, path, content);
    std::error_code ec;
    fs::rename(tmp, path, ec);
    if (ec) {
        fs::remove(tmp, ec);
        throw InputError(path.string(), "",
                         fs::is_directory(path, ec)
                             ? "cannot write it: a folder of that name is there"
                             : "cannot move the finished file into place");
    }
}

std::string read_file_bounded(const fs::path& path, std::size_t max_bytes, std::string_view what) {
    const std::string where = path.string();
    std::error_code ec;
    if (!fs::exists(path, ec))
        throw InputError(where, "", fmt::format("cannot read {}: no such file", what));
    if (fs::is_directory(path, ec))
        throw InputError(where, "", fmt::format("cannot read {}: it is a directory", what));
    constexpr std::size_t kStreamBytes = std::size_t(16) << 20;
    const std::size_t limit =
        fs::is_regular_file(path, ec) ? max_bytes : std::min(max_bytes, kStreamBytes);
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f)
        throw InputError(where, "", fmt::format("cannot read {}: {}", what, std::strerror(errno)));
    std::string text;
    std::vector<char> chunk(1 << 16);
    bool too_large = false;
    for (std::size_t n; (n = std::fread(chunk.data(), 1, chunk.size(), f)) > 0;) {
        if (text.size() + n > limit) {
            too_large = true;
            break;
        }
        text.append(chunk.data(), n);
    }
    const bool failed = std::ferror(f) != 0;
    std::fclose(f);
    if (too_large)
        throw InputError(where, "",
                         fmt::format("{} holds more than {} MiB{}", what, limit >> 20,
                                     limit < max_bytes ? " (it is not a regular file)" : ""));
    if (failed) throw InputError(where, "", fmt::format("cannot read {}", what));
    return text;
}

std::string read_regular_file_bounded(const fs::path& path, std::size_t max_bytes,
                                      std::string_view what) {
    std::error_code ec;
    if (fs::exists(path, ec) && !fs::is_directory(path, ec) && !fs::is_regular_file(path, ec))
        throw InputError(path.string(), "",
                         fmt::format("cannot read {}: it is not a regular file (a pipe or a "
                                     "device); lamina reads its own files only from regular ones",
                                     what));
    return read_file_bounded(path, max_bytes, what);
}

std::optional<std::string> read_cache_file(const fs::path& path, std::size_t max_bytes) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec) || ec) return std::nullopt;
    const std::uintmax_t size = fs::file_size(path, ec);
    if (ec || size > max_bytes) return std::nullopt;
    try {
        return read_file_bounded(path, max_bytes, "the cache entry");
    } catch (const InputError&) {
        return std::nullopt;
    }
}

bool file_holds(const fs::path& path, std::string_view content) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec) || fs::file_size(path, ec) != content.size() || ec)
        return false;
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return false;
    std::vector<char> buffer(1 << 16);
    std::size_t at = 0;
    bool same = true;
    while (same) {
        const std::size_t n = std::fread(buffer.data(), 1, buffer.size(), f);
        if (n == 0) break;
        same = at + n <= content.size() && std::memcmp(buffer.data(), content.data() + at, n) == 0;
        at += n;
    }
    std::fclose(f);
    return same && at == content.size();
}

bool write_file_if_changed(const fs::path& path, std::string_view content) {
    if (file_holds(path, content)) return false;
    write_file_atomic(path, content);
    return true;
}

StagedOutput::StagedOutput(fs::path dir, std::string field) : dir_(std::move(dir)) {
    if (dir_.empty())  // an option on the command line, an argument in Python
        throw InputError(field.rfind("--", 0) == 0 ? "command line" : "arguments", field,
                         "the output folder is an empty path; name a folder");
    std::error_code ec;
    // The folders create_directories will make, deepest first: the target and those of its
    // parents that are not there.
    for (fs::path p = dir_.lexically_normal(); !p.empty() && !fs::exists(p, ec);) {
        if (!p.has_filename()) {  // a trailing separator: the folder is its parent path
            p = p.parent_path();
            continue;
        }
        created_.push_back(p);
        if (!p.has_parent_path() || p.parent_path() == p) break;
        p = p.parent_path();
    }
    fs::create_directories(dir_, ec);
    if (ec || !fs::is_directory(dir_))
        throw InputError(dir_.string(), field, "cannot create the output folder: " + ec.message());
    if (::access(dir_.c_str(), W_OK) != 0)
        throw InputError(dir_.string(), field, "the output folder is not writable");
    remove_dead_staging(dir_);
    staging_ = dir_ / fmt::format(".staging-{}", unique_suffix());
    fs::create_directory(staging_, ec);
    if (ec)
        throw InputError(dir_.string(), field, "cannot create a staging folder: " + ec.message());
    slot_ = register_staging(staging_, created_.empty() ? fs::path() : created_.front(),
                             int(created_.size()));
}

StagedOutput::~StagedOutput() {
    if (slot_ >= 0) {
        g_slots[slot_].ready.store(false);
        g_slots[slot_].used.store(false);
    }
    std::error_code ec;
    fs::remove_all(staging_, ec);
    // A run that failed leaves no folder it made (remove deletes only an empty one).
    if (!committed_)
        for (const fs::path& made : created_)
            if (!fs::remove(made, ec)) break;
}

fs::path StagedOutput::stage_path(const std::string& name) {
    names_.push_back(name);
    return staging_ / name;
}

void StagedOutput::add(const std::string& name, std::string_view content) {
    write_all(staging_ / name, dir_ / name, content);
    names_.push_back(name);
}

bool StagedOutput::add_if_changed(const std::string& name, std::string_view content) {
    if (file_holds(dir_ / name, content)) return false;
    add(name, content);
    return true;
}

void StagedOutput::remove_unless_staged(const std::string& name) {
    stale_.push_back(name);
}

void StagedOutput::commit() {
    // A folder in the place of a file would fail its rename after the files before it had moved:
    // checked for every file first, so that a failed commit moves none.
    for (const auto& name : names_) {
        std::error_code ec;
        if (fs::is_directory(dir_ / name, ec))
            throw InputError((dir_ / name).string(), "",
                             "cannot write it: a folder of that name is there");
    }
    for (const auto& name : names_) {
        std::error_code ec;
        fs::rename(staging_ / name, dir_ / name, ec);
        if (ec) throw InputError((dir_ / name).string(), "", "cannot move the file into place");
    }
    for (const auto& name : stale_) {
        if (std::find(names_.begin(), names_.end(), name) != names_.end()) continue;
        std::error_code ec;
        fs::remove(dir_ / name, ec);  // absent is fine
        if (ec && fs::exists(dir_ / name))
            throw InputError((dir_ / name).string(), "",
                             "cannot remove this file of an earlier run: " + ec.message());
    }
    committed_ = true;
}

int register_interrupt_child(int pid, const fs::path& dir, const std::vector<std::string>& files) {
    const std::string d = dir.string();
    if (d.size() >= kPathBytes || files.size() > std::size_t(kChildFiles)) return -1;
    for (const std::string& f : files)
        if ((dir / f).string().size() >= kPathBytes) return -1;
    for (int i = 0; i < kChildSlots; ++i) {
        bool expected = false;
        if (g_children[i].used.load() ||
            !g_children[i].used.compare_exchange_strong(expected, true))
            continue;
        ChildSlot& slot = g_children[i];
        slot.pid = pid_t(pid);
        std::memcpy(slot.dir, d.c_str(), d.size() + 1);
        slot.n_files = int(files.size());
        for (std::size_t f = 0; f < files.size(); ++f) {
            const std::string path = (dir / files[f]).string();
            std::memcpy(slot.files[f], path.c_str(), path.size() + 1);
        }
        slot.ready.store(true);
        return i;
    }
    return -1;  // more than kChildSlots at once: not ended on an interrupt
}

void unregister_interrupt_child(int slot) {
    if (slot < 0 || slot >= kChildSlots) return;
    g_children[slot].ready.store(false);
    g_children[slot].used.store(false);
}

void remove_staging_on_interrupt() {
    struct sigaction action {};
    action.sa_handler = remove_staging_and_reraise;
    sigemptyset(&action.sa_mask);
    for (const int signal_number : {SIGINT, SIGTERM, SIGHUP})
        ::sigaction(signal_number, &action, nullptr);
}

}  // namespace lamina
