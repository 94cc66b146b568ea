#include "thread_pool.hpp"

#include <unistd.h>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>  // _mm_pause
#endif

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace principled_brdf {
namespace {

// How long a thread waits by polling before it sleeps: waking a sleeping
// thread costs tens of microseconds on a virtual machine (the idle virtual
// CPU halts), more than a call of 32,768 pairs takes on one core. A worker
// polls this long after each job, for the next call; the caller polls for
// its helpers to finish. The pause instruction keeps the poll light on an
// SMT sibling.
constexpr auto kPollFor = std::chrono::microseconds(200);

// Polls `ready` until it returns true (true) or kPollFor has passed (false).
template <class Ready>
bool poll(const Ready& ready) {
    const auto until = std::chrono::steady_clock::now() + kPollFor;
    for (;;) {
        for (int i = 0; i < 64; ++i) {
            if (ready()) return true;
#if defined(__x86_64__) || defined(__i386__)
            _mm_pause();
#endif
        }
        if (std::chrono::steady_clock::now() >= until) return false;
    }
}

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
            active_helpers_.store(helpers);
            generation_.store(generation_.load() + 1);
        }
        wake_.notify_all();  // (no system call when every worker is polling)
        drain();
        if (!poll([this] { return active_helpers_.load() == 0; })) {
            std::unique_lock<std::mutex> lock(mutex_);
            done_.wait(lock, [this] { return active_helpers_.load() == 0; });
        }
        task_ = nullptr;
    }

private:
    void drain() {
        for (int i = next_.fetch_add(1); i < count_; i = next_.fetch_add(1)) (*task_)(i);
    }

    void work() {
        unsigned long long seen = 0;
        for (;;) {
            poll([&] { return generation_.load() != seen; });
            {
                std::unique_lock<std::mutex> lock(mutex_);
                wake_.wait(lock, [&] { return stopping_ || (generation_.load() != seen && remaining_helpers_ > 0); });
                if (stopping_) return;
                seen = generation_.load();
                --remaining_helpers_;
            }
            drain();
            {
                // under the mutex, so that the caller cannot check and then sleep in between
                std::lock_guard<std::mutex> lock(mutex_);
                if (active_helpers_.fetch_sub(1) == 1) done_.notify_all();
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
    std::atomic<int> active_helpers_{0};
    std::atomic<unsigned long long> generation_{0};  // written under mutex_, polled without it
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
