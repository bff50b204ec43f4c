#pragma once
// Progress of long runs on stderr: rate and ETA, only when stderr is a terminal (quiet in pipes,
// logs and CI). Thread-safe: any thread may call advance().

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace lamina {

class Progress {
  public:
    /// `unit` names what is counted ("particles", "configurations"); `total` is how many.
    Progress(std::string label, std::string unit, std::uint64_t total);
    ~Progress();

    void advance(std::uint64_t n);
    /// Clears the progress line so that a caller can print a line of its own; the next advance()
    /// draws it again.
    void clear_line();
    /// Clears the line; called by the destructor too.
    void finish();

    static bool stderr_is_terminal();

  private:
    void draw(std::uint64_t done);

    std::string label_, unit_;
    std::uint64_t total_;
    std::atomic<std::uint64_t> done_{0};
    bool enabled_;
    bool finished_ = false;
    std::mutex mutex_;
    std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace lamina
