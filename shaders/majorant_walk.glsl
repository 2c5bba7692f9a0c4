// The majorant walk (render.comp): the media's majorants along a ray, the
// segments a free flight crosses (docs/rendering.md "Walking the cells").
// What a medium holds at a point is media.glsl's; what the path does at a
// tentative collision is the integrator's (tracking.glsl, vertex.glsl).

// A 3D DDA over a grid's majorant cells (Amanatides & Woo 1987): the cell the
// ray o + t·d is in and where it crosses each axis' next face. Stateless
// start: the cell is found at t + a small nudge along the ray, so a point on
// a face belongs to the cell being entered.
struct CellWalk {
  ivec3 cell, res, dir;
  vec3 t_axis, t_delta;
  uint offset;  // cell (0,0,0)'s index in the majorant buffer
};

CellWalk cell_walk(uint slot, vec3 o, vec3 d, float t, out float nudge) {
  CellWalk w;
  const vec3 u = density_texel(slot, o + t * d), du = density_texel_dir(slot, d);
  const vec3 cs = grids[slot].majorant_cell, inv_du = 1.0 / du;
  nudge = 1e-4 * min3(cs) / max(max3(abs(du)), 1e-30);
  w.res = ivec3(grids[slot].majorant_res);
  w.offset = grids[slot].majorant_offset;
  w.cell = clamp(ivec3(floor((u + du * nudge) / cs)), ivec3(0), w.res - 1);
  const vec3 tx = ((vec3(w.cell) + step(vec3(0.0), du)) * cs - u) * inv_du;
  w.t_axis = t + mix(tx, vec3(INF), isnan(tx));  // ±inf on axes the ray runs parallel to
  w.t_delta = abs(cs * inv_du);
  w.dir = ivec3(sign(du));
  return w;
}

uint cell_local(CellWalk w) { return uint((w.cell.z * w.res.y + w.cell.y) * w.res.x + w.cell.x); }

// Into the next cell along the ray; false once the ray has left the grid.
bool cell_step(inout CellWalk w) {
  const int a = w.t_axis.x <= w.t_axis.y ? (w.t_axis.x <= w.t_axis.z ? 0 : 2) : (w.t_axis.y <= w.t_axis.z ? 1 : 2);
  w.cell[a] += w.dir[a];
  if (w.cell[a] < 0 || w.cell[a] >= w.res[a]) return false;
  w.t_axis[a] += w.t_delta[a];
  return true;
}

// A cell's majorant; with `line` and the grid's line rates (the line
// estimator; docs/rendering.md "Emission estimators") the larger of it and the
// cell's rate, so the tentative collisions, where the collision estimator
// collects emission, come at least as often as the emission asks for.
float cell_majorant(uint slot, CellWalk w, bool line) {
  const uint local = cell_local(w), rates = grids[slot].line_rate_offset;
  const float sigma_maj = majorant_value(w.offset + local) * grids[slot].majorant_scale;
  return line && rates != 0u ? max(sigma_maj, majorant_value(rates + local)) : sigma_maj;
}

// Majorant of grid medium m over the DDA cell the ray is in at t, and the t at
// which the ray leaves that cell (the scenes with more than one medium:
// path_track restarts the free flight at every cell face).
float grid_majorant(GpuMedium m, vec3 o, vec3 d, float t, float t_span_end, bool line, inout float t_next) {
  const uint slot = m.grid_slot;
  float nudge;
  CellWalk w = cell_walk(slot, o, d, t, nudge);
  // At least a few float ulps of t, so t always moves on (a far camera loses
  // precision in u; see also the origin shift in path_begin).
  const float min_step = max(nudge, abs(t) * 1e-6);
  if (majorant_value(w.offset + cell_local(w)) > 0.0) {
    t_next = min(t_next, max(min3(w.t_axis), t + min_step));
    return cell_majorant(slot, w, line);
  }
  // An empty cell: walk the DDA on to the first non-empty cell (or out of the
  // grid) right here, so a run of empty cells costs one tracking step.
  float t_enter = min3(w.t_axis);
  for (uint n = 0u; n < 256u && t_enter < t_span_end; ++n) {
    if (!cell_step(w)) {
      t_enter = INF;  // left the grid: empty up to the span's end
      break;
    }
    if (majorant_value(w.offset + cell_local(w)) > 0.0) break;
    t_enter = min3(w.t_axis);
  }
  t_next = min(t_next, max(t_enter, t + min_step));
  return 0.0;
}

// One free flight of delta tracking through grid medium m's majorant cells,
// for scenes whose only medium is that grid (path_track): one exponential
// optical depth tau = −ln(1 − u) for the whole flight, spent cell by cell
// along the DDA (tau = Σ_j sigma_maj_j·Δt_j), so crossing a cell costs one DDA
// step instead of a pass of the tracking loop and its density lookup. The
// same distribution as restarting the flight at every face (the exponential
// is memoryless). Returns the majorant of the cell the flight collides in,
// with t moved to the collision; or 0 with t moved to t_end, or to where the
// walk's step budget ran out (the caller draws a fresh flight from there).
float grid_free_flight(GpuMedium m, vec3 o, vec3 d, inout float t, float t_end, bool line, float tau) {
  const uint slot = m.grid_slot;
  float nudge;
  CellWalk w = cell_walk(slot, o, d, t, nudge);
  for (uint n = 0u; n < 256u; ++n) {
    const float sigma_maj = cell_majorant(slot, w, line);
    const float t_exit = min(min3(w.t_axis), t_end);
    const float depth = sigma_maj * max(t_exit - t, 0.0);
    if (depth > tau) {
      t += tau / sigma_maj;
      return sigma_maj;
    }
    tau -= depth;
    t = max(t, t_exit);
    if (t >= t_end || !cell_step(w)) {
      t = t_end;
      break;
    }
  }
  return 0.0;
}

// Local majorant over [t, t_next): sum over the media present of their bound
// (with `line`, grids' line rates included: grid_majorant).
float majorant_at(vec3 o, vec3 d, float t, vec2 span[MEDIA_N], bool line, out float t_next, out bool any_ahead) {
  float sigma_maj = 0.0;
  t_next = INF;
  any_ahead = false;
  for (uint i = 0u; i < MEDIUM_COUNT; ++i) {
    vec2 s = span[i];
    if (s.y <= t) continue;
    any_ahead = true;
    if (s.x > t) {
      t_next = min(t_next, s.x);
      continue;
    }
    t_next = min(t_next, s.y);
    GpuMedium m = media[i];
    if (is_grid(m)) sigma_maj += grid_majorant(m, o, d, t, s.y, line, t_next);
    else {
      // A homogeneous medium's line rate: line_points along the ray's chord through it.
      const float chord = s.y - max(s.x, 0.0);
      const float sigma_t = max3(m.sigma_a + m.sigma_s);
      sigma_maj += line && m.line_points > 0.0 && chord > 0.0 ? max(sigma_t, m.line_points / chord) : sigma_t;
    }
  }
  return sigma_maj;
}
