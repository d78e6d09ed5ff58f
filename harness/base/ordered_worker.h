#pragma once
// A worker thread that consumes items one at a time, in the order they were submitted, from a
// bounded queue: the producer blocks while the queue is full, so memory stays bounded and the
// result is what one thread doing both in turn would get. An exception in the consumer stops the
// worker and is rethrown to the producer at its next submit() or at finish().
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>

namespace tgnav::harness {

template <typename T>
class OrderedWorker {
 public:
  OrderedWorker(std::size_t capacity, std::function<void(T&)> consume)
      : capacity_(capacity > 0 ? capacity : 1), consume_(std::move(consume)), thread_([this] { run(); }) {}
  ~OrderedWorker() { stop(); }
  OrderedWorker(const OrderedWorker&) = delete;
  OrderedWorker& operator=(const OrderedWorker&) = delete;
  OrderedWorker(OrderedWorker&&) = delete;  // owns a thread that captures `this`
  OrderedWorker& operator=(OrderedWorker&&) = delete;

  void submit(T item) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return queue_.size() < capacity_ || error_; });
    if (error_) std::rethrow_exception(error_);
    queue_.push_back(std::move(item));
    changed_.notify_all();
  }

  // Waits until every submitted item is consumed; rethrows the consumer's exception.
  void finish() {
    stop();
    if (error_) std::rethrow_exception(error_);
  }

 private:
  void run() {
    for (;;) {
      T item;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return !queue_.empty() || stopping_; });
        if (queue_.empty()) return;  // stopping, all consumed
        item = std::move(queue_.front());
        queue_.pop_front();
        changed_.notify_all();
      }
      try {
        consume_(item);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex_);
        error_ = std::current_exception();
        queue_.clear();
        changed_.notify_all();
        return;
      }
    }
  }

  void stop() {
    if (!thread_.joinable()) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
      changed_.notify_all();
    }
    thread_.join();
  }

  std::size_t capacity_;
  std::function<void(T&)> consume_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<T> queue_;
  bool stopping_ = false;
  std::exception_ptr error_;
  std::thread thread_;  // last: starts once everything it uses exists
};

}  // namespace tgnav::harness
