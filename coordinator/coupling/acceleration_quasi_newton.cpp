#include "coupling/acceleration_quasi_newton.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <utility>

#include "coupling/acceleration_filtered_qr.hpp"
#include "coupling/checkpoint_encoding.hpp"

namespace robin {
namespace {

int total_size(const std::vector<RelaxationBlock>& blocks) {
  int size = 0;
  for (const RelaxationBlock& block : blocks) size += block.size;
  return size;
}

}  // namespace

IqnIlsAcceleration::IqnIlsAcceleration(std::vector<RelaxationBlock> blocks,
                                       QuasiNewtonParameters parameters)
    : size_(total_size(blocks)),
      blocks_(blocks),
      parameters_(parameters),
      relaxation_(std::move(blocks)) {}

Eigen::VectorXd IqnIlsAcceleration::next(const Eigen::VectorXd& iterate,
                                         const Eigen::VectorXd& mapped) {
  assert(iterate.size() == size_ && mapped.size() == size_);
  // r_k = H(x_k) - x_k
  const Eigen::VectorXd residual = mapped - iterate;
  columns_ = 0;
  filtered_ = 0;
  if (has_previous_) record_differences(residual, mapped);
  previous_residual_ = residual;
  previous_mapped_ = mapped;
  has_previous_ = true;
  if (!residual_differences_.empty()) {
    const Eigen::VectorXd alpha = least_squares_coefficients(residual);
    if (alpha.size() > 0) {
      previous_was_quasi_newton_ = true;
      return quasi_newton_step(iterate, mapped, alpha);
    }
  }
  previous_was_quasi_newton_ = false;
  if (parameters_.mixing == QuasiNewtonMixing::aitken && !mixing_.empty()) {
    return mixed(iterate, mapped, mixing_);
  }
  return relaxation_.next(iterate, mapped);
}

Eigen::VectorXd IqnIlsAcceleration::mixed(const Eigen::VectorXd& point,
                                          const Eigen::VectorXd& image,
                                          const std::vector<double>& mixing) const {
  Eigen::VectorXd result(size_);
  Eigen::Index start = 0;
  for (std::size_t index = 0; index < blocks_.size(); ++index) {
    const int size = blocks_[index].size;
    const double beta = mixing[index];
    // (1 - beta) x + beta h on the block
    result.segment(start, size) =
        (1.0 - beta) * point.segment(start, size) + beta * image.segment(start, size);
    start += size;
  }
  return result;
}

void IqnIlsAcceleration::record_differences(const Eigen::VectorXd& residual,
                                            const Eigen::VectorXd& mapped) {
  const double growth = residual.norm() / previous_residual_.norm();
  if (previous_was_quasi_newton_ && growth > parameters_.safeguard_growth) {
    clear_history();
    ++safeguard_restarts_;
    reason_ = "restart: the residual grew " + format_for_state(growth) + "x";
    return;
  }
  // V <- [r_k - r_{k-1}, V],  W <- [x~_k - x~_{k-1}, W]
  residual_differences_.push_front(residual - previous_residual_);
  mapped_differences_.push_front(mapped - previous_mapped_);
  while (static_cast<int>(residual_differences_.size()) > parameters_.history_depth) {
    residual_differences_.pop_back();
    mapped_differences_.pop_back();
  }
}

Eigen::VectorXd IqnIlsAcceleration::least_squares_coefficients(const Eigen::VectorXd& residual) {
  const int count = static_cast<int>(residual_differences_.size());
  Eigen::MatrixXd differences(size_, count);
  for (int column = 0; column < count; ++column) {
    differences.col(column) = residual_differences_[column];
  }
  const FilteredQr factors = filtered_qr(differences, parameters_.filter_threshold);
  const int kept = static_cast<int>(factors.kept.size());
  filtered_ = count - kept;
  if (filtered_ > 0) {
    std::deque<Eigen::VectorXd> kept_residual, kept_mapped;
    for (const int column : factors.kept) {
      kept_residual.push_back(residual_differences_[column]);
      kept_mapped.push_back(mapped_differences_[column]);
    }
    residual_differences_ = std::move(kept_residual);
    mapped_differences_ = std::move(kept_mapped);
  }
  if (kept == 0) {
    clear_history();
    reason_ = "restart: the filter dropped every column";
    return {};
  }
  columns_ = kept;
  // R alpha = -Q' r_k
  return factors.r.triangularView<Eigen::Upper>().solve(-(factors.q.transpose() * residual));
}

Eigen::VectorXd IqnIlsAcceleration::quasi_newton_step(const Eigen::VectorXd& iterate,
                                                      const Eigen::VectorXd& mapped,
                                                      const Eigen::VectorXd& alpha) {
  // h^ = x~_k + W alpha
  Eigen::VectorXd predicted = mapped;
  for (Eigen::Index column = 0; column < alpha.size(); ++column) {
    predicted += alpha(column) * mapped_differences_[column];
  }
  if (parameters_.mixing == QuasiNewtonMixing::full) {
    mixing_.assign(blocks_.size(), 1.0);
    return predicted;
  }
  // x^ = x_k + (W - V) alpha
  Eigen::VectorXd combination = iterate;
  for (Eigen::Index column = 0; column < alpha.size(); ++column) {
    combination += alpha(column) * (mapped_differences_[column] - residual_differences_[column]);
  }
  mixing_.resize(blocks_.size());
  Eigen::Index start = 0;
  for (std::size_t index = 0; index < blocks_.size(); ++index) {
    mixing_[index] = block_mixing(blocks_[index], start);
    start += blocks_[index].size;
  }
  // x_{k+1} = (1 - beta) x^ + beta h^ per block
  return mixed(combination, predicted, mixing_);
}

double IqnIlsAcceleration::block_mixing(const RelaxationBlock& block, Eigen::Index start) const {
  if (parameters_.mixing == QuasiNewtonMixing::relaxation) return block.relaxation;
  // beta = -dx'dv / |dv|^2 with dv = V_0, dx = W_0 - V_0 on the block
  const auto residual_change = residual_differences_.front().segment(start, block.size);
  const auto mapped_change = mapped_differences_.front().segment(start, block.size);
  const double denominator = residual_change.squaredNorm();
  if (!(denominator > 0.0)) return block.relaxation;
  const double secant = -(mapped_change - residual_change).dot(residual_change) / denominator;
  const double magnitude =
      std::clamp(std::abs(secant), parameters_.mixing_minimum, parameters_.mixing_maximum);
  return std::copysign(magnitude, secant);
}

void IqnIlsAcceleration::clear_history() {
  residual_differences_.clear();
  mapped_differences_.clear();
}

std::string IqnIlsAcceleration::state() const {
  if (columns_ == 0) return "iqn-ils relaxation step (" + reason_ + ")";
  std::string line =
      "iqn-ils " + std::to_string(columns_) + (columns_ == 1 ? " column" : " columns");
  if (filtered_ > 0) line += " (" + std::to_string(filtered_) + " filtered)";
  if (parameters_.mixing == QuasiNewtonMixing::full) return line;
  line += ", beta = ";
  if (mixing_.size() > 1) line += "(";
  for (std::size_t index = 0; index < mixing_.size(); ++index) {
    if (index > 0) line += ", ";
    line += format_for_state(mixing_[index]);
  }
  if (mixing_.size() > 1) line += ")";
  return line;
}

void IqnIlsAcceleration::restart() {
  clear_history();
  has_previous_ = false;
  previous_was_quasi_newton_ = false;
  columns_ = 0;
  filtered_ = 0;
  mixing_.clear();
  reason_ = "first step after a restart";
}

nlohmann::json IqnIlsAcceleration::save_state() const {
  return {{"method", "iqn-ils"},
          {"size", size_},
          {"residual_differences", encode_vectors(residual_differences_)},
          {"mapped_differences", encode_vectors(mapped_differences_)},
          {"has_previous", has_previous_},
          {"previous_was_quasi_newton", previous_was_quasi_newton_},
          {"previous_residual", encode_vector(previous_residual_)},
          {"previous_mapped", encode_vector(previous_mapped_)},
          {"columns", columns_},
          {"filtered", filtered_},
          {"safeguard_restarts", safeguard_restarts_},
          {"mixing", encode_numbers(mixing_)},
          {"reason", reason_}};
}

void IqnIlsAcceleration::restore_state(const nlohmann::json& state) {
  if (decode_text(state, "method") != "iqn-ils" || decode_integer(state, "size") != size_) {
    throw CheckpointFormatError("the checkpoint's acceleration is not 'iqn-ils' of size " +
                                std::to_string(size_));
  }
  std::deque<Eigen::VectorXd> residual_differences = decode_vectors(state, "residual_differences");
  std::deque<Eigen::VectorXd> mapped_differences = decode_vectors(state, "mapped_differences");
  const auto sized = [this](const std::deque<Eigen::VectorXd>& columns) {
    return std::all_of(columns.begin(), columns.end(),
                       [this](const Eigen::VectorXd& column) { return column.size() == size_; });
  };
  if (residual_differences.size() != mapped_differences.size() || !sized(residual_differences) ||
      !sized(mapped_differences)) {
    throw CheckpointFormatError("the checkpoint's iqn-ils columns do not match its size");
  }
  residual_differences_ = std::move(residual_differences);
  mapped_differences_ = std::move(mapped_differences);
  has_previous_ = decode_flag(state, "has_previous");
  previous_was_quasi_newton_ = decode_flag(state, "previous_was_quasi_newton");
  previous_residual_ = decode_vector(state, "previous_residual");
  previous_mapped_ = decode_vector(state, "previous_mapped");
  columns_ = decode_integer(state, "columns");
  filtered_ = decode_integer(state, "filtered");
  safeguard_restarts_ = decode_integer(state, "safeguard_restarts");
  mixing_ = decode_numbers(state, "mixing");
  reason_ = decode_text(state, "reason");
}

}  // namespace robin
