#include "thread_pool.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace principled_brdf {
namespace {

class ThreadPool {
public:
    explicit ThreadPool(int workers) {
        for (int i = 0; i < workers; ++i) threads_.emplace_back([this] { work(); });
    }

    ~ThreadPool() {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            stopping_ = true;
        }
        wake_.notify_all();
        for (std::thread& t : threads_) t.join();
    }

    int workers() const { return static_cast<int>(threads_.size()); }

    void run(int count, int helpers, const std::function<void(int)>& task) {
        std::lock_guard<std::mutex> one_job_at_a_time(job_mutex_);
        {
            std::lock_guard<std::mutex> lock(mutex_);
            task_ = &task;
            count_ = count;
            next_.store(0);
            remaining_helpers_ = helpers;
            active_helpers_ = helpers;
            ++generation_;
        }
        wake_.notify_all();
        drain();
        std::unique_lock<std::mutex> lock(mutex_);
        done_.wait(lock, [this] { return active_helpers_ == 0; });
        task_ = nullptr;
    }

private:
    void drain() {
        for (int i = next_.fetch_add(1); i < count_; i = next_.fetch_add(1)) (*task_)(i);
    }

    void work() {
        unsigned long long seen = 0;
        for (;;) {
            {
                std::unique_lock<std::mutex> lock(mutex_);
                wake_.wait(lock, [&] { return stopping_ || (generation_ != seen && remaining_helpers_ > 0); });
                if (stopping_) return;
                seen = generation_;
                --remaining_helpers_;
            }
            drain();
            {
                std::lock_guard<std::mutex> lock(mutex_);
                if (--active_helpers_ == 0) done_.notify_all();
            }
        }
    }

    std::vector<std::thread> threads_;
    std::mutex job_mutex_;  // one parallel_for at a time; others wait
    std::mutex mutex_;
    std::condition_variable wake_, done_;
    const std::function<void(int)>* task_ = nullptr;
    int count_ = 0;
    std::atomic<int> next_{0};
    int remaining_helpers_ = 0;
    int active_helpers_ = 0;
    unsigned long long generation_ = 0;
    bool stopping_ = false;
};

// The pool belongs to the process that made it: after fork() the child's copy
// has no threads, so the child makes its own (the parent's is left alone).
ThreadPool& pool() {
    static std::mutex mutex;
    static pid_t owner = 0;
    static ThreadPool* instance = nullptr;
    std::lock_guard<std::mutex> lock(mutex);
    if (instance == nullptr || owner != getpid()) {
        const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
        instance = new ThreadPool(cores - 1);  // never destroyed: workers may outlive static destruction order
        owner = getpid();
    }
    return *instance;
}

}  // namespace

void parallel_for(int count, int threads, const std::function<void(int)>& task) {
    if (count <= 0) return;
    if (threads <= 1 || count == 1) {
        for (int i = 0; i < count; ++i) task(i);
        return;
    }
    ThreadPool& p = pool();
    p.run(count, std::min({threads - 1, count - 1, p.workers()}), task);
}

}  // namespace principled_brdf
