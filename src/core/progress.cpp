#include "core/progress.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>

namespace lamina {

namespace {
std::string human(double x) {
    if (x >= 1e9) return fmt::format("{:.2f} G", x / 1e9);
    if (x >= 1e6) return fmt::format("{:.2f} M", x / 1e6);
    if (x >= 1e3) return fmt::format("{:.2f} k", x / 1e3);
    return fmt::format("{:.0f} ", x);
}
std::string duration(double s) {
    if (s < 60) return fmt::format("{:.0f}s", s);
    if (s < 3600) return fmt::format("{}m{:02}s", int(s / 60), int(s) % 60);
    return fmt::format("{}h{:02}m", int(s / 3600), int(s / 60) % 60);
}
}  // namespace

bool Progress::stderr_is_terminal() {
    return ::isatty(STDERR_FILENO) == 1;
}

Progress::Progress(std::string label, std::string unit, std::uint64_t total)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      total_(total),
      enabled_(stderr_is_terminal()),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

Progress::~Progress() {
    finish();
}

void Progress::advance(std::uint64_t n) {
    const std::uint64_t done = done_.fetch_add(n) + n;
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_draw_ < std::chrono::milliseconds(250)) return;
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() || finished_) return;
    last_draw_ = now;
    draw(done);
}

void Progress::draw(std::uint64_t done) {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double rate = elapsed > 0 ? double(done) / elapsed : 0.0;
    const double eta = rate > 0 ? double(total_ - std::min(done, total_)) / rate : 0.0;
    const double pct = total_ ? 100.0 * double(done) / double(total_) : 100.0;
    std::fprintf(stderr, "\r\033[K%s: %5.1f%%  %s%s/s  ETA %s", label_.c_str(), pct,
                 human(rate).c_str(), unit_.c_str(), duration(eta).c_str());
    std::fflush(stderr);
}

void Progress::clear_line() {
    if (!enabled_) return;
    std::lock_guard lock(mutex_);
    std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
}

void Progress::finish() {
    if (!enabled_) return;
    std::lock_guard lock(mutex_);
    if (finished_) return;
    finished_ = true;
    std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
}

}  // namespace lamina
