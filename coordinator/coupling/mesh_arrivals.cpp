#include "coupling/mesh_arrivals.hpp"

#include <stdexcept>
#include <string>

namespace robin {

MeshArrivals::MeshArrivals(std::size_t bodies) : arrived_(bodies, false) {}

void MeshArrivals::arrive(std::size_t body) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (body >= arrived_.size()) {
      throw std::out_of_range("MeshArrivals::arrive: body " + std::to_string(body) + " of " +
                              std::to_string(arrived_.size()));
    }
    arrived_[body] = true;
    last_arrival_ = Clock::now();
    if (!first_arrival_) first_arrival_ = last_arrival_;
  }
  changed_.notify_all();
}

void MeshArrivals::abandon() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    abandoned_ = true;
  }
  changed_.notify_all();
}

bool MeshArrivals::wait(std::size_t body) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (body >= arrived_.size()) {
    throw std::out_of_range("MeshArrivals::wait: body " + std::to_string(body) + " of " +
                            std::to_string(arrived_.size()));
  }
  changed_.wait(lock, [&] { return arrived_[body] || abandoned_; });
  return arrived_[body];
}

std::optional<MeshArrivals::Clock::time_point> MeshArrivals::first_arrival() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return first_arrival_;
}

std::optional<MeshArrivals::Clock::time_point> MeshArrivals::last_arrival() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return last_arrival_;
}

}  // namespace robin
