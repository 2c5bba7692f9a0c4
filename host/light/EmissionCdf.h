#pragma once
// An emissive grid medium as a light: a discrete distribution over the cells of
// its density texture, proportional to (a conservative estimate of) the emitted
// luminance in each cell, and a uniform point inside the chosen cell
// (docs/lights.md).
//
// Cells. The density texture's texel centres sit at integer cell coordinates
// c = index − origin (texel i at c = i); cell (i, j, k) is the parallelepiped
// c ∈ [i, i+1) × [j, j+1) × [k, k+1) in world space, and its 8 corners are
// exactly the 8 texels every trilinear lookup inside it blends. There are
// (dims − 1) cells per axis; together they are the texture's support (the
// density is 0 outside).
//
// Weight of a cell (one number, emitted luminance per unit volume):
//   w = ρ_max · E_max,
//   ρ_max = the largest of its 8 corner density texels (values as stored),
//   E_max = the largest E(T) over the temperature texels whose trilinear
//           footprint reaches into the cell (and E(T(0)) when the footprint
//           leaves the temperature texture, whose outside reads 0),
//   E(T)  = Y(σa ⊙ Le(T)): sRGB luminance, σa = sigma_a · density_scale,
//           Le = emission.scale · blackbody_rgb_5nm(T) with the CPU reference's
//           rules (color/EmissionModel.h temperature_Le);
//           T = (value − offset) · scale. Constant-rgb emission: E = Y(σa ⊙ Le_rgb).
// The emission at x, σa·ρ(x)·Le(T(x)), is > 0 only if ρ(x) > 0 and
// T(x) > cutoff; trilinear values are convex combinations of the corners, so
// then ρ_max > 0 and some footprint texel has T > cutoff: every point that
// emits has pdf > 0, and the light sampler is unbiased (the integrand is not
// piecewise constant, so the distribution only approximates it).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "scene/Scene.h"
#include "volume/DenseGrid.h"
#include "volume/StoredVolume.h"

namespace pyrolume {

// A point sampled inside an emissive medium.
struct EmissionSample {
  glm::dvec3 p{0.0};  // world space
  double pdf = 0.0;   // VOLUME measure (1/unit³); 0: no sample. Solid angle from a
                      // point x: pdf · |p − x|² (no cosine: a medium has no surface)
  int64_t cell = -1;  // linear cell index x + X·(y + Y·z)
};

// What the weight needs from a medium.
struct EmissionParams {
  glm::dvec3 sigma_a{1.0};  // per unit stored density: sigma_a · density_scale
  bool emits_rgb = false;   // Le = Le_rgb everywhere
  glm::dvec3 Le_rgb{0.0};   // emission.scale · emission.rgb
  bool emits_temperature = false;  // Le from the temperature grid
  TemperatureMapping temperature;
  Emission emission;  // blackbody mode, observer, adapt_to_k, scale

  // The medium's parameters, as host/render/cpu/Media.cpp reads them.
  static EmissionParams from_medium(const Medium& m);
};

class EmissionCdf {
 public:
  EmissionCdf() = default;

  // For a vdb medium whose grids are loaded (load_stored_volume).
  static EmissionCdf build(const Medium& m, const StoredVolume& vol);
  // From grids directly. temperature may be null (then emits_temperature emits
  // nothing, as in the renderers).
  static EmissionCdf build(const DenseGrid& density, const DenseGrid* temperature, const EmissionParams& p);

  // No emission anywhere (zero density, all temperatures at or below the cutoff,
  // σa = 0, no grid): no distribution. sample() returns pdf 0, pdf() is 0.
  bool empty() const { return cdf_.empty(); }
  glm::ivec3 cells() const { return cells_; }
  size_t cell_count() const { return size_t(cells_.x) * size_t(cells_.y) * size_t(cells_.z); }
  size_t entry_count() const { return cdf_.size(); }  // cells of weight > 0
  double cell_volume() const { return cell_volume_; }
  // ∫ w dV = Σ w · cell volume: an upper estimate of ∫ Y(σa ρ Le) dV, for
  // choosing between lights by power.
  double power() const { return power_; }
  double seconds_to_build() const { return build_seconds_; }

  // For a sparse density grid (volume/SparseGrid.h), a distribution over
  // blocks of b³ cells made from the trees alone, with no per-cell arrays (a
  // 1024³ box has 10⁹ cells). A block's weight is Σρ · E_max: the density of
  // every nonzero voxel that is a corner of one of its cells, times the
  // largest E(T) over the temperature voxels within one voxel of the block
  // (from the lowest and highest value: E grows with T; and E(T(0)), the
  // value where no voxel is).
  // A point that emits has a corner with ρ > 0 and a footprint texel with
  // T > cutoff, so its block's weight is > 0: unbiased, as build()'s.
  static EmissionCdf build_sparse_blocks(const DenseGrid& density, const DenseGrid* temperature,
                                         const EmissionParams& p, int b);
  // Up to this many cells a sparse grid's light is build()'s, made through
  // lookups in the tree (the per-cell arrays take 8 B a cell); past it,
  // build_sparse_blocks'.
  static constexpr uint64_t kMaxCellsForCellLight = uint64_t(1) << 23;
  // The same distribution over blocks of b³ cells (the grid of blocks covers
  // the cells, the last ones may reach past them): a block's probability is
  // the sum of its cells', and a point is uniform inside the block. Lights in
  // the renderers use blocks of light_block(cells()): next-event estimation
  // needs the pdf of a whole direction, a sum over every cell the ray crosses
  // (direction_pdf), and ≤ kLightBlocksPerAxis blocks per axis keep that walk
  // short (docs/mis.md).
  EmissionCdf blocks(int b) const;
  static constexpr int kLightBlocksPerAxis = 24;
  // The same distribution seen from a receiver o (docs/mis.md "Seen from the
  // receiver"): the cells are grouped into clusters of k³ cells, and a
  // cluster s is chosen with probability ∝ I_s(o) = Φ_s / max(|o − c_s|², r_s²)
  // (Φ_s its share of the distribution above, c_s and r_s the world-space
  // bounding sphere of its cells of weight > 0), then a cell inside it by its
  // share of Φ_s. A cluster's light falls off as 1/distance² from the
  // receiver; the bound r_s keeps I_s finite inside. Applies to sample_from,
  // pdf_from and direction_pdf.
  EmissionCdf clustered(int k) const;
  static constexpr int kLightClustersPerAxis = 6;
  // What both renderers sample:
  // build(m, vol).blocks(light_block(...)).clustered(light_cluster(...)).
  static EmissionCdf build_light(const Medium& m, const StoredVolume& vol);
  static int light_block(const glm::ivec3& cells);
  static int light_cluster(const glm::ivec3& cells) { return light_block(cells, kLightClustersPerAxis); }
  static int light_block(const glm::ivec3& cells, int per_axis);
  bool is_clustered() const { return !clusters_.empty(); }

  // The unnormalised weight w of a cell and its probability (as stored, float).
  double cell_weight(const glm::ivec3& c) const;
  double cell_pmf(int64_t cell) const { return pmf_.empty() ? 0.0 : double(pmf_[size_t(cell)]); }
  int64_t linear_cell(const glm::ivec3& c) const {
    return (int64_t(c.z) * cells_.y + c.y) * cells_.x + c.x;
  }

  glm::dvec3 world_to_cell(const glm::dvec3& p) const { return glm::dvec3(world_to_cell_ * glm::dvec4(p, 1.0)); }
  glm::dvec3 cell_to_world(const glm::dvec3& c) const { return glm::dvec3(cell_to_world_ * glm::dvec4(c, 1.0)); }

  // u picks the cell (searching the float CDF like the GPU); u3 ∈ [0,1)³ the
  // point inside it: p = cell_to_world(cell + u3), pdf = pmf / cell volume.
  EmissionSample sample(double u, const glm::dvec3& u3) const;
  // The volume pdf of the cell containing world point p (0 outside every cell).
  double pdf(const glm::dvec3& p) const;
  // Seen from receiver o: the same as sample() and pdf() unless clustered.
  // norm: receiver_norm(o), which a caller asking several times from one o
  // may compute once.
  double receiver_norm(const glm::dvec3& o) const;
  // u picks the cluster, u_cell the cell inside it (like sample()'s u), u3 the point.
  EmissionSample sample_from(const glm::dvec3& o, double u, double u_cell, const glm::dvec3& u3) const {
    return sample_from(o, receiver_norm(o), u, u_cell, u3);
  }
  EmissionSample sample_from(const glm::dvec3& o, double norm, double u, double u_cell, const glm::dvec3& u3) const;
  double pdf_from(const glm::dvec3& o, const glm::dvec3& p) const { return pdf_from(o, receiver_norm(o), p); }
  double pdf_from(const glm::dvec3& o, double norm, const glm::dvec3& p) const;
  // The solid-angle pdf at o of direction w (unit) toward a point drawn by
  // sample_from(o, …): ∫₀^∞ pdf_from(o, o + t·w) t² dt, exactly, over the
  // cells the ray crosses.
  double direction_pdf(const glm::dvec3& o, const glm::dvec3& w) const {
    return direction_pdf(o, receiver_norm(o), w);
  }
  double direction_pdf(const glm::dvec3& o, double norm, const glm::dvec3& w) const;

  // ---- the clustered layout (render/vulkan/LightPacking.h packs it) ----
  const std::vector<float>& cluster_cdf() const { return local_cdf_; }  // per entry, inclusive within its cluster
  const std::vector<uint32_t>& entry_cells() const { return entries_; }  // grouped by cluster
  const std::vector<float>& cluster_pmf() const { return local_pmf_; }  // one per cell, within its cluster
  // A cluster of k³ cells (clustered()).
  struct Cluster {
    glm::dvec3 centre{0.0};   // world-space bounding sphere of its cells of weight > 0
    double radius2 = 0.0;
    double power = 0.0;       // Φ_s: Σ of its cells' weights / Σ of all (0: empty)
    uint32_t first = 0, count = 0;  // its entries
  };
  const std::vector<Cluster>& clusters() const { return clusters_; }  // dense over the cluster grid
  glm::ivec3 cluster_dims() const { return cluster_dims_; }
  int cluster_cells_per_axis() const { return cluster_k_; }           // k
  size_t nonempty_clusters() const;                                   // clusters with cells of weight > 0
  const glm::dmat4& cell_to_world_matrix() const { return cell_to_world_; }
  const glm::dmat4& world_to_cell_matrix() const { return world_to_cell_; }

 private:
  // The float CDF over entries_ (weights w, one per entry) and the per-cell pmf.
  void set_distribution(const std::vector<double>& w);
  // I_s(o) of cluster s; and the cluster of a cell (clustered only).
  double cluster_importance(const glm::dvec3& o, size_t s) const;
  size_t cluster_of(const glm::ivec3& cell) const;
  // The cell coordinates of a linear cell index.
  glm::ivec3 cell_coords(uint32_t cell) const;
  // The first index in [lo, hi] whose inclusive CDF exceeds u (hi if none):
  // the search lights.glsl's emission_sample does.
  static uint32_t first_above(const std::vector<float>& cdf, uint32_t lo, uint32_t hi, double u);
  // Visits the cells the ray o + t·w (w unit) crosses, by 3D DDA: f(cell, t0, t1).
  template <class F>
  void walk_cells(const glm::dvec3& o, const glm::dvec3& w, F f) const;

  glm::ivec3 cells_{0};
  glm::dmat4 cell_to_world_{1.0}, world_to_cell_{1.0};
  double cell_volume_ = 0.0;
  double power_ = 0.0;
  double build_seconds_ = 0.0;
  std::vector<float> weight_;     // w per cell (float; for inspection and tests)
  std::vector<float> pmf_;        // per cell
  std::vector<float> cdf_;        // per entry
  std::vector<uint32_t> entries_; // per entry

  // clustered(): entries_ are grouped by cluster (then ascending).
  int cluster_k_ = 0;              // cells per cluster per axis
  glm::ivec3 cluster_dims_{0};
  std::vector<Cluster> clusters_;  // dense over the cluster grid, linear like cells
  std::vector<float> local_cdf_;   // per entry: inclusive CDF within its cluster
  std::vector<float> local_pmf_;   // per cell: probability within its cluster
};

}  // namespace pyrolume
