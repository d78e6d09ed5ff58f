#pragma once
// The VO stage of a trial: camera noise, then tracking, frame after frame in submission order.
// The noise is added on the submitting thread (the simulation's, which has time to spare while
// the VO tracks), the tracking on a worker thread (threaded: the simulation renders the next
// frames meanwhile) or inline. A frame's noise and result do not depend on the mode, so a
// pipelined trial equals a sequential one.
#include <Eigen/Geometry>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <opencv2/core.hpp>
#include <thread>
#include <vector>

#include "harness/sim/camera.h"
#include "vo/odometry.h"

namespace tgnav::harness {

class VoPipeline {
 public:
  struct Done {
    vo::FrameResult vo;
    Eigen::Isometry3d X_WC_true;
    cv::Mat image;                   // the noised image, when asked to keep it (and at the first loss)
    RgbdFrame::Timing frame_timing;  // rendering and noise (wall clock; vo.timing has tracking's)
  };

  VoPipeline(vo::RgbdOdometry& odometry, CameraNoise& noise, bool reinitialises, bool threaded)
      : odometry_(odometry), noise_(noise), reinitialises_(reinitialises) {
    if (threaded) worker_ = std::thread([this] { run(); });
  }
  ~VoPipeline() { stopWorker(); }
  VoPipeline(const VoPipeline&) = delete;
  VoPipeline& operator=(const VoPipeline&) = delete;

  // Adds the noise, then tracks the frame (inline) or queues it (threaded). Returns the seconds
  // it waited for room in the queue.
  double submit(RgbdFrame frame, bool keep_image) {
    noise_.apply(&frame);
    if (!worker_.joinable()) {
      process(Job{std::move(frame), keep_image});
      return 0.0;
    }
    const auto t0 = std::chrono::steady_clock::now();
    std::unique_lock<std::mutex> lock(mutex_);
    // A short queue bounds memory; the simulation runs at most this far ahead of the VO.
    changed_.wait(lock, [&] { return queue_.size() < kQueueCapacity || error_; });
    const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    rethrowLocked();
    queue_.push_back(Job{std::move(frame), keep_image});
    changed_.notify_all();
    return waited;
  }

  // The result of the k-th submitted frame, waiting for it.
  Done result(std::size_t k) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return done_.size() > k || error_; });
    rethrowLocked();
    return done_[k];
  }

  // Frames the simulation may submit before the VO has started on them.
  static constexpr std::size_t kQueueCapacity = 3;

  // Whether some frame processed so far was lost for good (no re-initialisation).
  bool failedForGood() const { return failed_for_good_.load(); }

  std::vector<Done> finish() {
    stopWorker();
    std::lock_guard<std::mutex> lock(mutex_);
    rethrowLocked();
    return std::move(done_);
  }

 private:
  struct Job {
    RgbdFrame frame;
    bool keep_image;
  };

  void process(Job job) {
    const bool failed_before = odometry_.failed();
    Done d{odometry_.track(job.frame.t_s, job.frame.bgr, job.frame.depth_m), job.frame.X_WC, cv::Mat(),
           job.frame.timing};
    const bool first_loss = !failed_before && odometry_.failed();
    if (job.keep_image || first_loss) d.image = job.frame.bgr;
    if (odometry_.failed() && !reinitialises_) failed_for_good_.store(true);
    std::lock_guard<std::mutex> lock(mutex_);
    done_.push_back(std::move(d));
    changed_.notify_all();
  }

  void run() {
    for (;;) {
      Job job;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return !queue_.empty() || stop_; });
        if (queue_.empty()) return;  // stopping, all done
        job = std::move(queue_.front());
        queue_.pop_front();
        changed_.notify_all();
      }
      try {
        process(std::move(job));
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex_);
        error_ = std::current_exception();
        changed_.notify_all();
        return;
      }
    }
  }

  void stopWorker() {
    if (!worker_.joinable()) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
      changed_.notify_all();
    }
    worker_.join();
  }

  void rethrowLocked() const {
    if (error_) std::rethrow_exception(error_);
  }

  vo::RgbdOdometry& odometry_;
  CameraNoise& noise_;
  bool reinitialises_;
  std::thread worker_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Job> queue_;
  std::vector<Done> done_;
  bool stop_ = false;
  std::exception_ptr error_;
  std::atomic<bool> failed_for_good_{false};
};

}  // namespace tgnav::harness
