#include "host/vk/build_pool.h"

#include <algorithm>

namespace mcd::vk {

BuildPool::~BuildPool() {
    {
        std::lock_guard<std::mutex> lock(mutex);
        stopping = true;
    }
    wake.notify_all();
    for (std::thread &worker : workers) worker.join();
}

std::shared_future<void> BuildPool::Run(std::function<void()> task, bool ahead,
                                        uint64_t *ticket) {
    std::packaged_task<void()> packaged(std::move(task));
    std::shared_future<void> done = packaged.get_future().share();
    if (ticket) *ticket = 0;
    if (threads <= 1) {
        packaged();
        return done;
    }
    {
        std::lock_guard<std::mutex> lock(mutex);
        uint64_t id = nextTicket++;
        if (ticket) *ticket = id;
        (ahead ? later : queue).emplace_back(id, std::move(packaged));
        if (workers.empty())
            for (int i = 0; i < threads; ++i) workers.emplace_back([this] { Work(); });
    }
    wake.notify_one();
    return done;
}

void BuildPool::Hasten(uint64_t ticket) {
    std::lock_guard<std::mutex> lock(mutex);
    auto it = std::find_if(later.begin(), later.end(),
                           [&](const auto &entry) { return entry.first == ticket; });
    if (it == later.end()) return;
    queue.push_back(std::move(*it));
    later.erase(it);
}

std::packaged_task<void()> BuildPool::Take(uint64_t ticket) {
    for (Queue *from : {&queue, &later}) {
        auto it = std::find_if(from->begin(), from->end(),
                               [&](const auto &entry) { return entry.first == ticket; });
        if (it == from->end()) continue;
        std::packaged_task<void()> task = std::move(it->second);
        from->erase(it);
        return task;
    }
    return {};
}

void BuildPool::NoteIfIdle() {
    if (queue.empty() && later.empty() && running == 0) idle.notify_all();
}

void BuildPool::RunHere(uint64_t ticket) {
    std::packaged_task<void()> task;
    {
        std::lock_guard<std::mutex> lock(mutex);
        task = Take(ticket);
        if (!task.valid()) return;
        ++running;
    }
    task();  // an exception lands in the task's future
    std::lock_guard<std::mutex> lock(mutex);
    --running;
    NoteIfIdle();
}

void BuildPool::Drop(uint64_t ticket) {
    std::packaged_task<void()> task;
    {
        std::lock_guard<std::mutex> lock(mutex);
        task = Take(ticket);
        if (!task.valid()) return;
        NoteIfIdle();
    }
    // The task destroyed unrun leaves its future ready with a broken promise.
}

void BuildPool::Wait() {
    std::unique_lock<std::mutex> lock(mutex);
    idle.wait(lock, [this] { return queue.empty() && later.empty() && running == 0; });
}

void BuildPool::Work() {
    std::unique_lock<std::mutex> lock(mutex);
    for (;;) {
        wake.wait(lock, [this] { return stopping || !queue.empty() || !later.empty(); });
        if (queue.empty() && later.empty()) return;
        // The tasks asked for now first: a submission waits for them.
        Queue &from = queue.empty() ? later : queue;
        std::packaged_task<void()> task = std::move(from.front().second);
        from.pop_front();
        ++running;
        lock.unlock();
        task();  // an exception lands in the task's future
        lock.lock();
        --running;
        NoteIfIdle();
    }
}

}  // namespace mcd::vk
