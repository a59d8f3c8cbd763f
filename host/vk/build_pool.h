// Threads that build pipelines while the caller goes on recording: a kernel asked for
// during recording is built on one of them, and the recorder waits for it only when it
// submits (host/vk/recorder.h), so the kernels a submission needs build side by side.
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

namespace mcd::vk {

class BuildPool {
  public:
    // `threads` workers, started on the first task; 0 or 1: each task runs in Run itself.
    explicit BuildPool(int threads) : threads(threads) {}
    ~BuildPool();
    BuildPool(const BuildPool &) = delete;
    BuildPool &operator=(const BuildPool &) = delete;

    // `task` queued for a worker (or run now, without workers); the future holds its
    // exception, if any.
    std::shared_future<void> Run(std::function<void()> task);
    // Waits until every queued task has finished.
    void Wait();

  private:
    void Work();

    int threads = 0;
    std::vector<std::thread> workers;
    std::deque<std::packaged_task<void()>> queue;
    std::mutex mutex;
    std::condition_variable wake, idle;
    int running = 0;
    bool stopping = false;
};

}  // namespace mcd::vk
