// Threads that build pipelines while the caller goes on recording: a kernel asked for
// during recording is built on one of them, and the recorder waits for it only when it
// submits (host/vk/recorder.h), so the kernels a submission needs build side by side.
// Builds asked for ahead of their use (Context::PrepareKernel) wait behind those asked for
// now, unless hastened when they are asked for in turn.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <future>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

namespace mcd::vk {

class BuildPool {
  public:
    // `threads` workers, started on the first task; 0 or 1: each task runs in Run itself.
    explicit BuildPool(int threads) : threads(threads) {}
    ~BuildPool();
    BuildPool(const BuildPool &) = delete;
    BuildPool &operator=(const BuildPool &) = delete;

    // Whether tasks run beside the caller (more than one thread).
    bool HasWorkers() const { return threads > 1; }
    // `task` queued for a worker (or run now, without workers); the future holds its
    // exception, if any. `ahead`: a task for later, taken only when no other waits (run
    // now without workers all the same); `ticket`, if given, names it for Hasten.
    std::shared_future<void> Run(std::function<void()> task, bool ahead = false,
                                 uint64_t *ticket = nullptr);
    // Moves a task queued ahead to the back of the others, if no worker has taken it yet.
    void Hasten(uint64_t ticket);
    // Runs the task in the caller, if no worker has taken it yet: one who would wait for it
    // builds it instead.
    void RunHere(uint64_t ticket);
    // Forgets the task, if no worker has taken it yet: its future is then ready at once, with
    // a broken promise, and the task never runs (a kernel dropped before its build).
    void Drop(uint64_t ticket);
    // Waits until every queued task has finished.
    void Wait();

  private:
    void Work();
    // Takes the task named `ticket` out of either queue; an empty task if none holds it.
    // Called with `mutex` held.
    std::packaged_task<void()> Take(uint64_t ticket);
    // Wakes Wait if nothing is queued or running. Called with `mutex` held.
    void NoteIfIdle();

    using Queue = std::deque<std::pair<uint64_t, std::packaged_task<void()>>>;
    int threads = 0;
    std::vector<std::thread> workers;
    Queue queue, later;
    std::mutex mutex;
    std::condition_variable wake, idle;
    uint64_t nextTicket = 1;
    int running = 0;
    bool stopping = false;
};

}  // namespace mcd::vk
