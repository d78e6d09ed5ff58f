#pragma once
// The VO stage of a trial: camera noise, feature extraction, then tracking, frame after frame in
// submission order. Threaded, the noise and the features run on one worker and the tracking on
// another (the simulation renders the next frames meanwhile), otherwise inline. The noise is
// drawn frame after frame in order on either, so a frame's noise and result do not depend on the
// mode: a pipelined trial equals a sequential one.
#include <Eigen/Geometry>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <vector>

#include "harness/base/ordered_worker.h"
#include "harness/sim/camera.h"
#include "vo/odometry.h"

namespace tgnav::harness {

class VoPipeline {
 public:
  struct Done {
    vo::FrameResult vo;
    Eigen::Isometry3d X_WC_true;
    cv::Mat image;                   // the noised image, when asked to keep it (and at the first loss)
    RgbdFrame::Timing frame_timing;  // rendering and noise, wall clock (vo.timing: the VO's)
    RgbdFrame::Timing frame_cpu;     // ... and CPU (vo.cpu: the VO's)
  };

  // Threaded: one worker prepares the frames (noise, ORB and back-projection, which do not depend
  // on the odometry's state), another tracks them; each takes frames in order from a queue of
  // kQueueCapacity.
  VoPipeline(vo::RgbdOdometry& odometry, CameraNoise& noise, bool reinitialises, bool threaded)
      : odometry_(odometry), noise_(noise), reinitialises_(reinitialises) {
    if (!threaded) return;
    tracker_ =
        std::make_unique<OrderedWorker<Prepared>>(kQueueCapacity, [this](Prepared& p) { guarded([&] { track(p); }); });
    preparer_ = std::make_unique<OrderedWorker<Job>>(
        kQueueCapacity, [this](Job& job) { guarded([&] { tracker_->submit(prepare(std::move(job))); }); });
  }
  ~VoPipeline() {
    preparer_.reset();  // drains into the tracker first
    tracker_.reset();
  }
  VoPipeline(const VoPipeline&) = delete;
  VoPipeline& operator=(const VoPipeline&) = delete;
  VoPipeline(VoPipeline&&) = delete;  // its workers capture `this`
  VoPipeline& operator=(VoPipeline&&) = delete;

  // Noises, prepares and tracks the frame (inline) or queues it (threaded). Returns the seconds
  // it waited for room in the queue.
  double submit(RgbdFrame frame, bool keep_image) {
    if (!preparer_) {
      track(prepare(Job{std::move(frame), keep_image}));
      return 0.0;
    }
    const auto t0 = std::chrono::steady_clock::now();
    preparer_->submit(Job{std::move(frame), keep_image});
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }

  // The result of the k-th submitted frame, waiting for it.
  Done result(std::size_t k) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return done_.size() > k || error_; });
    if (error_) std::rethrow_exception(error_);
    return done_[k];
  }

  // Frames a stage may queue for the next before that one has started on them.
  static constexpr std::size_t kQueueCapacity = 3;

  // Whether some frame processed so far was lost for good (no re-initialisation).
  bool failedForGood() const { return failed_for_good_.load(); }

  std::vector<Done> finish() {
    if (preparer_) preparer_->finish();
    if (tracker_) tracker_->finish();
    std::lock_guard<std::mutex> lock(mutex_);
    if (error_) std::rethrow_exception(error_);
    return std::move(done_);
  }

 private:
  struct Job {
    RgbdFrame frame;
    bool keep_image = false;
  };
  struct Prepared {
    vo::RgbdOdometry::PreparedFrame vo;
    RgbdFrame frame;  // its images stay for the strip, the pose for the scores
    bool keep_image = false;
  };

  // Frames come here one at a time, in submission order: the noise's random stream stays in order.
  Prepared prepare(Job job) {
    noise_.apply(&job.frame);
    vo::RgbdOdometry::PreparedFrame prepared = odometry_.prepare(job.frame.t_s, job.frame.bgr, job.frame.depth_m);
    return Prepared{std::move(prepared), std::move(job.frame), job.keep_image};
  }

  void track(const Prepared& p) {
    const bool failed_before = odometry_.failed();
    Done d{odometry_.track(p.vo), p.frame.X_WC, cv::Mat(), p.frame.timing, p.frame.cpu};
    const bool first_loss = !failed_before && odometry_.failed();
    if (p.keep_image || first_loss) d.image = p.frame.bgr;
    if (odometry_.failed() && !reinitialises_) failed_for_good_.store(true);
    std::lock_guard<std::mutex> lock(mutex_);
    done_.push_back(std::move(d));
    changed_.notify_all();
  }

  // A worker's step; its exception also reaches result(), which may be waiting.
  template <typename Fn>
  void guarded(Fn step) {
    try {
      step();
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!error_) error_ = std::current_exception();
      changed_.notify_all();
      throw;
    }
  }

  vo::RgbdOdometry& odometry_;
  CameraNoise& noise_;
  bool reinitialises_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<Done> done_;
  std::exception_ptr error_;
  std::atomic<bool> failed_for_good_{false};
  std::unique_ptr<OrderedWorker<Prepared>> tracker_;
  std::unique_ptr<OrderedWorker<Job>> preparer_;
};

}  // namespace tgnav::harness
