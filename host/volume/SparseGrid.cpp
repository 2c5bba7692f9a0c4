#include "volume/SparseGrid.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <type_traits>

namespace pyrolume {

void SparseGrid::move_to(void* memory) const {
  const uint64_t n = handle.size();
  std::memcpy(memory, handle.data(), n);
  handle = nanovdb::GridHandle<nanovdb::HostBuffer>(nanovdb::HostBuffer::createFull(n, memory));
}

float SparseGrid::value(const glm::ivec3& ijk) const {
  return grid().tree().getValue(nanovdb::Coord(ijk.x, ijk.y, ijk.z));
}

double SparseGrid::sample_index(const glm::dvec3& index_pos) const {
  const glm::dvec3 x0 = glm::floor(index_pos);
  // Beyond int32 no leaf exists (also guards the conversion).
  for (int a = 0; a < 3; ++a)
    if (!(std::abs(x0[a]) < 2.0e9)) return 0.0;
  const glm::ivec3 i0(x0);
  const glm::dvec3 f = index_pos - x0;
  auto acc = grid().getAccessor();  // one accessor: the 8 corners mostly share a leaf
  double v = 0.0;
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = c >> 2;
    const double w = (dx ? f.x : 1.0 - f.x) * (dy ? f.y : 1.0 - f.y) * (dz ? f.z : 1.0 - f.z);
    if (w != 0.0) v += w * double(acc.getValue(nanovdb::Coord(i0.x + dx, i0.y + dy, i0.z + dz)));
  }
  return v;
}

void SparseGrid::for_each_nonzero(const std::function<void(const glm::ivec3&, float)>& f) const {
  const auto& tree = grid().tree();
  const uint64_t n = tree.nodeCount(0);
  if (n == 0) return;
  const auto* leaf = tree.getFirstNode<0>();
  for (uint64_t l = 0; l < n; ++l, ++leaf) {
    const nanovdb::Coord o = leaf->origin();
    for (uint32_t i = 0; i < 512; ++i) {
      const float v = leaf->getValue(i);
      if (v == 0.0f) continue;
      f(glm::ivec3(o[0] + int(i >> 6), o[1] + int((i >> 3) & 7), o[2] + int(i & 7)), v);
    }
  }
  for_each_tile([&](const glm::ivec3& o, int size, float v) {
    for (int k = 0; k < size; ++k)
      for (int j = 0; j < size; ++j)
        for (int i = 0; i < size; ++i) f(o + glm::ivec3(i, j, k), v);
  });
}

void SparseGrid::for_each_tile(const std::function<void(const glm::ivec3&, int, float)>& f) const {
  const auto& tree = grid().tree();
  auto visit = [&](const auto* node, uint64_t count) {
    using Node = std::remove_cv_t<std::remove_pointer_t<decltype(node)>>;
    for (uint64_t i = 0; i < count; ++i, ++node)
      for (uint32_t n = 0; n < Node::SIZE; ++n) {
        if (node->data()->isChild(n)) continue;
        const float v = node->data()->getValue(n);
        if (v == 0.0f) continue;
        const nanovdb::Coord o = node->offsetToGlobalCoord(n);
        f(glm::ivec3(o[0], o[1], o[2]), int(Node::ChildNodeType::DIM), v);
      }
  };
  if (tree.nodeCount(1)) visit(tree.getFirstNode<1>(), tree.nodeCount(1));
  if (tree.nodeCount(2)) visit(tree.getFirstNode<2>(), tree.nodeCount(2));
}

void SparseGrid::for_each_leaf(const std::function<void(const glm::ivec3&, uint64_t)>& f) const {
  const auto& tree = grid().tree();
  const uint64_t n = tree.nodeCount(0);
  if (n == 0) return;
  const auto* base = reinterpret_cast<const char*>(handle.data());
  const auto* leaf = tree.getFirstNode<0>();
  for (uint64_t l = 0; l < n; ++l, ++leaf) {
    const nanovdb::Coord o = leaf->origin();
    const auto* values = reinterpret_cast<const char*>(&leaf->data()->mValues[0]);
    f(glm::ivec3(o[0], o[1], o[2]), uint64_t(values - base));
  }
}

uint64_t nanovdb_float_bytes(uint64_t leaves, uint64_t lowers, uint64_t uppers) {
  constexpr uint64_t kHeaders = sizeof(nanovdb::GridData) + sizeof(nanovdb::TreeData<3>) + sizeof(nanovdb::NanoRoot<float>);
  return kHeaders + leaves * sizeof(nanovdb::NanoLeaf<float>) + lowers * sizeof(nanovdb::NanoLower<float>) +
         uppers * (sizeof(nanovdb::NanoUpper<float>) + sizeof(nanovdb::NanoRoot<float>::Tile));
}

}  // namespace pyrolume
