#include "numerics/galerkin_product.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace robin {
namespace {

/// C's block lower triangle in compressed block rows: the blocks J <= I of each block row I in
/// increasing J, bc x bc values each, row by row.
struct LowerBlocks {
  std::vector<int> starts;
  std::vector<int> columns;
  std::vector<double> values;
};

/// The fine blocks j with an entry A_rc, r in block i and c in block j, for every i.
std::vector<std::vector<int>> fine_block_graph(const RowMajorSparseMatrix& matrix,
                                               const BlockLayout& fine) {
  std::vector<std::vector<int>> graph(static_cast<std::size_t>(fine.count()));
  std::vector<int> seen(static_cast<std::size_t>(fine.count()), -1);
  for (int i = 0; i < fine.count(); ++i) {
    for (int k = fine.first(i); k < fine.first(i + 1); ++k) {
      const int row = fine.members()[static_cast<std::size_t>(k)];
      for (RowMajorSparseMatrix::InnerIterator entry(matrix, row); entry; ++entry) {
        const int j = fine.block_of(static_cast<int>(entry.col()));
        if (seen[static_cast<std::size_t>(j)] == i) continue;
        seen[static_cast<std::size_t>(j)] = i;
        graph[static_cast<std::size_t>(i)].push_back(j);
      }
    }
  }
  return graph;
}

/// The block pattern of C's lower triangle: C_IJ, J <= I, is stored when some fine block i has
/// P_iI and (A P)_iJ, the latter when some neighbour j of i has P_jJ.
LowerBlocks lower_pattern(const std::vector<std::vector<int>>& graph,
                          const BlockSparseMatrix<double>& prolongator) {
  const int coarse_count = prolongator.column_layout().count();
  const std::vector<int>& starts = prolongator.block_starts();
  const std::vector<int>& columns = prolongator.block_columns();
  std::vector<std::vector<int>> rows(static_cast<std::size_t>(coarse_count));
  std::vector<int> seen(static_cast<std::size_t>(coarse_count), -1);
  std::vector<int> reached;
  for (int i = 0; i < static_cast<int>(graph.size()); ++i) {
    reached.clear();
    for (int j : graph[static_cast<std::size_t>(i)]) {
      for (int k = starts[static_cast<std::size_t>(j)]; k < starts[static_cast<std::size_t>(j) + 1];
           ++k) {
        const int J = columns[static_cast<std::size_t>(k)];
        if (seen[static_cast<std::size_t>(J)] == i) continue;
        seen[static_cast<std::size_t>(J)] = i;
        reached.push_back(J);
      }
    }
    for (int k = starts[static_cast<std::size_t>(i)]; k < starts[static_cast<std::size_t>(i) + 1];
         ++k) {
      const int I = columns[static_cast<std::size_t>(k)];
      for (int J : reached) {
        if (J <= I) rows[static_cast<std::size_t>(I)].push_back(J);
      }
    }
  }
  LowerBlocks lower;
  lower.starts.assign(static_cast<std::size_t>(coarse_count) + 1, 0);
  for (int I = 0; I < coarse_count; ++I) {
    std::vector<int>& row = rows[static_cast<std::size_t>(I)];
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
    lower.starts[static_cast<std::size_t>(I) + 1] =
        lower.starts[static_cast<std::size_t>(I)] + static_cast<int>(row.size());
    lower.columns.insert(lower.columns.end(), row.begin(), row.end());
    std::vector<int>().swap(row);
  }
  const long area = static_cast<long>(prolongator.column_layout().block_size()) *
                    prolongator.column_layout().block_size();
  lower.values.assign(lower.columns.size() * static_cast<std::size_t>(area), 0.0);
  return lower;
}

/// (A P)_i: the br x bc blocks of fine block row i, one per coarse block in `touched` (in the
/// order first reached), row by row in `blocks`; `position` (-1 for every coarse block on entry
/// and on return) is workspace.
void multiply_block_row(const RowMajorSparseMatrix& matrix,
                        const BlockSparseMatrix<double>& prolongator, int i,
                        std::vector<int>& position, std::vector<int>& touched,
                        std::vector<double>& blocks) {
  const BlockLayout& fine = prolongator.row_layout();
  const int br = fine.block_size(), bc = prolongator.column_layout().block_size();
  const long area = static_cast<long>(br) * bc;
  const std::vector<int>& starts = prolongator.block_starts();
  const std::vector<int>& columns = prolongator.block_columns();
  const double* values = prolongator.values().data();
  touched.clear();
  for (int a = 0; a < br; ++a) {
    const int row = fine.unknown_of_slot(br * i + a);
    if (row < 0) continue;
    for (RowMajorSparseMatrix::InnerIterator entry(matrix, row); entry; ++entry) {
      const int column = static_cast<int>(entry.col());
      const int j = fine.block_of(column);
      const long slot = fine.slot_of(column) - br * j;
      const double value = entry.value();
      for (int k = starts[static_cast<std::size_t>(j)]; k < starts[static_cast<std::size_t>(j) + 1];
           ++k) {
        const int J = columns[static_cast<std::size_t>(k)];
        int& place = position[static_cast<std::size_t>(J)];
        if (place < 0) {
          place = static_cast<int>(touched.size());
          touched.push_back(J);
          blocks.resize(touched.size() * static_cast<std::size_t>(area));
          std::fill(blocks.end() - area, blocks.end(), 0.0);
        }
        const double* source = values + area * k + bc * slot;
        double* target = blocks.data() + area * place + static_cast<long>(bc) * a;
        for (int c = 0; c < bc; ++c) target[c] += value * source[c];
      }
    }
  }
  for (int J : touched) position[static_cast<std::size_t>(J)] = -1;
}

/// C_IJ += P_iI' (A P)_iJ over the blocks J <= I of (A P)_i.
void add_block_row(const BlockSparseMatrix<double>& prolongator, int i,
                   const std::vector<int>& touched, const std::vector<double>& blocks,
                   LowerBlocks& lower) {
  const int br = prolongator.row_layout().block_size();
  const int bc = prolongator.column_layout().block_size();
  const long area = static_cast<long>(br) * bc, coarse_area = static_cast<long>(bc) * bc;
  const std::vector<int>& starts = prolongator.block_starts();
  for (int k = starts[static_cast<std::size_t>(i)]; k < starts[static_cast<std::size_t>(i) + 1];
       ++k) {
    const int I = prolongator.block_columns()[static_cast<std::size_t>(k)];
    const double* left = prolongator.values().data() + area * k;
    const int* row_begin = lower.columns.data() + lower.starts[static_cast<std::size_t>(I)];
    const int* row_end = lower.columns.data() + lower.starts[static_cast<std::size_t>(I) + 1];
    for (std::size_t t = 0; t < touched.size(); ++t) {
      const int J = touched[t];
      if (J > I) continue;
      const long place = std::lower_bound(row_begin, row_end, J) - lower.columns.data();
      double* target = lower.values.data() + coarse_area * place;
      const double* right = blocks.data() + area * static_cast<long>(t);
      for (int a = 0; a < br; ++a) {
        for (int x = 0; x < bc; ++x) {
          const double factor = left[a * bc + x];
          if (factor == 0.0) continue;
          for (int y = 0; y < bc; ++y) target[x * bc + y] += factor * right[a * bc + y];
        }
      }
    }
  }
}

/// Both triangles of C in compressed rows from its block lower triangle: each block below the
/// diagonal written twice (C_IJ and its transpose), the diagonal blocks symmetrized, the padding
/// left out; each row's columns sorted.
RowMajorSparseMatrix assemble_symmetric(const LowerBlocks& lower, const BlockLayout& coarse) {
  const int bc = coarse.block_size();
  const long coarse_area = static_cast<long>(bc) * bc;
  RowMajorSparseMatrix result(coarse.size(), coarse.size());
  int* starts = result.outerIndexPtr();
  std::fill(starts, starts + coarse.size() + 1, 0);
  const auto visit = [&](auto&& write) {
    for (int I = 0; I < coarse.count(); ++I) {
      for (int k = lower.starts[static_cast<std::size_t>(I)];
           k < lower.starts[static_cast<std::size_t>(I) + 1]; ++k) {
        const int J = lower.columns[static_cast<std::size_t>(k)];
        const double* block = lower.values.data() + coarse_area * k;
        for (int x = 0; x < bc; ++x) {
          const int row = coarse.unknown_of_slot(bc * I + x);
          if (row < 0) continue;
          for (int y = 0; y < bc; ++y) {
            const int column = coarse.unknown_of_slot(bc * J + y);
            if (column < 0) continue;
            if (J == I) {
              write(row, column, 0.5 * (block[x * bc + y] + block[y * bc + x]));
            } else {
              write(row, column, block[x * bc + y]);
              write(column, row, block[x * bc + y]);
            }
          }
        }
      }
    }
  };
  visit([&](int row, int, double) { ++starts[row + 1]; });
  for (int row = 0; row < coarse.size(); ++row) starts[row + 1] += starts[row];
  result.resizeNonZeros(starts[coarse.size()]);
  std::vector<int> next(starts, starts + coarse.size());
  int* columns = result.innerIndexPtr();
  double* values = result.valuePtr();
  visit([&](int row, int column, double value) {
    const int place = next[static_cast<std::size_t>(row)]++;
    columns[place] = column;
    values[place] = value;
  });
  std::vector<std::pair<int, double>> entries;
  for (int row = 0; row < coarse.size(); ++row) {
    if (std::is_sorted(columns + starts[row], columns + starts[row + 1])) continue;
    entries.clear();
    for (int k = starts[row]; k < starts[row + 1]; ++k) entries.emplace_back(columns[k], values[k]);
    std::sort(entries.begin(), entries.end());
    for (int k = starts[row]; k < starts[row + 1]; ++k) {
      columns[k] = entries[static_cast<std::size_t>(k - starts[row])].first;
      values[k] = entries[static_cast<std::size_t>(k - starts[row])].second;
    }
  }
  return result;
}

}  // namespace

RowMajorSparseMatrix galerkin_product(const RowMajorSparseMatrix& matrix,
                                      const BlockSparseMatrix<double>& prolongator) {
  const BlockLayout& fine = prolongator.row_layout();
  if (matrix.rows() != fine.size() || matrix.cols() != fine.size()) {
    throw std::invalid_argument("galerkin_product: the prolongator does not match the matrix");
  }
  LowerBlocks lower = lower_pattern(fine_block_graph(matrix, fine), prolongator);
  std::vector<int> position(static_cast<std::size_t>(prolongator.column_layout().count()), -1);
  std::vector<int> touched;
  std::vector<double> blocks;
  for (int i = 0; i < fine.count(); ++i) {
    multiply_block_row(matrix, prolongator, i, position, touched, blocks);
    add_block_row(prolongator, i, touched, blocks, lower);
  }
  return assemble_symmetric(lower, prolongator.column_layout());
}

}  // namespace robin
