// How far a long job is, on stderr: on a terminal one line redrawn in place; anywhere else
// (a log file, a farm's job output) a plain line every few seconds with the fraction done
// and an estimate of the time left, so that a run writing to a log shows it is alive.
#pragma once

#include <chrono>
#include <string>

namespace mcd::tool {

// "4.2 s", "3m07s", "2h05m".
std::string DurationText(double seconds);

class Progress {
  public:
    // `task` starts every line: "render cornell 256x256 at 16 spp", "denoise".
    explicit Progress(std::string task);
    // Ends a redrawn line, so what follows starts on a line of its own.
    ~Progress();
    Progress(const Progress &) = delete;
    Progress &operator=(const Progress &) = delete;

    // `stage` ("" for the whole job) is `done` of `total` along. A plain line gives the
    // job's time so far and the stage's time left, from the stage's pace.
    void Update(const std::string &stage, double done, double total);
    // A part of the job starts now (a frame's run): its first stage's pace is measured from
    // here, not from the work before it.
    void Begin();
    // Before other output on stderr or stdout: takes a redrawn line off the terminal.
    void Clear();
    // The job is done: a redrawn line stays, ended.
    void Done();
    // Whether stderr is a terminal (lines are redrawn in place).
    bool Terminal() const { return terminal; }
    // Seconds between plain lines: $MCD_PROGRESS_SECONDS, else 5 (0: every update).
    static double IntervalSeconds();

  private:
    using Clock = std::chrono::steady_clock;
    std::string task, stage;
    bool terminal, drawn = false;
    double interval;
    // A stage starts at the update before its first (a stage reports once some is done).
    Clock::time_point start = Clock::now(), stageStart = start, lastUpdate = start,
                      lastLine = start;
};

}  // namespace mcd::tool
