#include "core/atomic_file.h"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace lamina {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
    const fs::path dir =
        fs::temp_directory_path() / ("lamina-atomic-" + std::to_string(::getpid()) + "-" + name);
    fs::remove_all(dir);
    return dir;
}

// A run that fails after its output folder was made (an exception out of the simulation, a
// bad_alloc) leaves nothing: neither the staged files nor the folder it created.
TEST(StagedOutput, FailureLeavesNoFolderItMade) {
    const fs::path dir = fresh_dir("fail") / "out";
    try {
        StagedOutput out(dir);
        out.add("result.json", "{}");
        ASSERT_TRUE(fs::is_directory(dir));
        throw std::runtime_error("the run failed");
    } catch (const std::runtime_error&) {
    }
    EXPECT_FALSE(fs::exists(dir));
    fs::remove_all(dir.parent_path());
}

// A run killed outright (SIGKILL: no handler) leaves its staging folder; the next run into the
// folder removes it, and never the staging folder of a process that is alive.
TEST(StagedOutput, RemovesTheStagingOfADeadProcessOnly) {
    const fs::path dir = fresh_dir("dead");
    fs::create_directories(dir);
    const pid_t child = ::fork();
    if (child == 0) ::_exit(0);
    ASSERT_GT(child, 0);
    ASSERT_EQ(::waitpid(child, nullptr, 0), child);  // reaped: its PID is no process now
    const fs::path dead = dir / (".staging-" + std::to_string(child) + ".0");
    const fs::path alive = dir / (".staging-" + std::to_string(::getppid()) + ".0");
    const fs::path other = dir / ".staging-notapid";
    for (const fs::path& p : {dead, alive, other})
        fs::create_directories(p / "inside");
    {
        StagedOutput out(dir);
        out.add("result.json", "{}");
        out.commit();
    }
    EXPECT_FALSE(fs::exists(dead));
    EXPECT_TRUE(fs::exists(alive / "inside"));
    EXPECT_TRUE(fs::exists(other / "inside"));
    EXPECT_TRUE(fs::exists(dir / "result.json"));
    fs::remove_all(dir);
}

// A folder that was there before keeps its files, and the failed run's staged files never reach
// it; a committed run's files are in place.
TEST(StagedOutput, FailureKeepsAFolderThatWasThere) {
    const fs::path dir = fresh_dir("kept");
    fs::create_directories(dir);
    write_file_atomic(dir / "old.csv", "earlier");
    try {
        StagedOutput out(dir);
        out.add("new.csv", "staged");
        throw std::runtime_error("the run failed");
    } catch (const std::runtime_error&) {
    }
    EXPECT_TRUE(fs::exists(dir / "old.csv"));
    EXPECT_FALSE(fs::exists(dir / "new.csv"));
    {
        StagedOutput out(dir);
        out.add("new.csv", "committed");
        out.commit();
    }
    EXPECT_TRUE(file_holds(dir / "new.csv", "committed"));
    for (const auto& entry : fs::directory_iterator(dir))
        EXPECT_EQ(entry.path().filename().string().rfind(".staging", 0), std::string::npos);
    fs::remove_all(dir);
}

}  // namespace
}  // namespace lamina
