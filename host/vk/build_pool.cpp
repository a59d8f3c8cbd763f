#include "host/vk/build_pool.h"

namespace mcd::vk {

BuildPool::~BuildPool() {
    {
        std::lock_guard<std::mutex> lock(mutex);
        stopping = true;
    }
    wake.notify_all();
    for (std::thread &worker : workers) worker.join();
}

std::shared_future<void> BuildPool::Run(std::function<void()> task) {
    std::packaged_task<void()> packaged(std::move(task));
    std::shared_future<void> done = packaged.get_future().share();
    if (threads <= 1) {
        packaged();
        return done;
    }
    {
        std::lock_guard<std::mutex> lock(mutex);
        queue.push_back(std::move(packaged));
        if (workers.empty())
            for (int i = 0; i < threads; ++i) workers.emplace_back([this] { Work(); });
    }
    wake.notify_one();
    return done;
}

void BuildPool::Wait() {
    std::unique_lock<std::mutex> lock(mutex);
    idle.wait(lock, [this] { return queue.empty() && running == 0; });
}

void BuildPool::Work() {
    std::unique_lock<std::mutex> lock(mutex);
    for (;;) {
        wake.wait(lock, [this] { return stopping || !queue.empty(); });
        if (queue.empty()) return;
        std::packaged_task<void()> task = std::move(queue.front());
        queue.pop_front();
        ++running;
        lock.unlock();
        task();  // an exception lands in the task's future
        lock.lock();
        --running;
        if (queue.empty() && running == 0) idle.notify_all();
    }
}

}  // namespace mcd::vk
