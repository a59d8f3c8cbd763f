#include "tools/mcdenoise/progress.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <utility>

namespace mcd::tool {

std::string DurationText(double s) {
    if (s < 60) return fmt::format("{:.1f} s", s);
    if (s < 3600) return fmt::format("{}m{:02d}s", int(s) / 60, int(s) % 60);
    return fmt::format("{}h{:02d}m", int(s) / 3600, int(s) / 60 % 60);
}

Progress::Progress(std::string task)
    : task(std::move(task)), terminal(isatty(fileno(stderr))), interval(IntervalSeconds()) {}

Progress::~Progress() {
    if (drawn) std::fprintf(stderr, "\n");
}

double Progress::IntervalSeconds() {
    const char *text = std::getenv("MCD_PROGRESS_SECONDS");
    char *end = nullptr;
    double seconds = text ? std::strtod(text, &end) : 5;
    return text && *end == '\0' && seconds >= 0 ? seconds : 5;
}

void Progress::Update(const std::string &newStage, double done, double total) {
    Clock::time_point now = Clock::now();
    if (newStage != stage) stage = newStage, stageStart = lastUpdate;
    lastUpdate = now;
    double fraction = total > 0 ? std::clamp(done / total, 0.0, 1.0) : 0;
    std::string name = stage.empty() ? task : task + ": " + stage;
    if (terminal) {
        std::fprintf(stderr, "\r\033[K%s %3d%%", name.c_str(), int(100 * fraction));
        std::fflush(stderr);
        drawn = true;
        return;
    }
    if (std::chrono::duration<double>(now - lastLine).count() < interval) return;
    lastLine = now;
    // The time left from the stage's own pace: its time so far over its fraction done.
    double inStage = std::chrono::duration<double>(now - stageStart).count();
    std::string left = fraction > 0 && fraction < 1
                           ? fmt::format(", about {} left{}",
                                         DurationText(inStage * (1 - fraction) / fraction),
                                         stage.empty() ? "" : " in this stage")
                           : "";
    std::fprintf(stderr, "%s %d%% after %s%s\n", name.c_str(), int(100 * fraction),
                 DurationText(std::chrono::duration<double>(now - start).count()).c_str(),
                 left.c_str());
    std::fflush(stderr);
}

void Progress::Begin() {
    stage.clear();
    lastUpdate = Clock::now();
}

void Progress::Done() {
    if (drawn) std::fprintf(stderr, "\n");
    drawn = false;
}

void Progress::Clear() {
    if (drawn) std::fprintf(stderr, "\r\033[K");
    drawn = false;
}

}  // namespace mcd::tool
