// Fast, exact voting for Algorithm 1.
//
// Per theta bin the plain algorithm rotates every edge pixel, groups them into rows of Rot and
// checks every pair of every row against [Dmin, Dmax]. The same votes are cast here with far less
// work per vote:
//  * Rotation is integer fixed-point (quantise.hpp) in a loop the compiler vectorises; rows are
//    built with one counting sort.
//  * Pairs are checked 16 or 32 at a time without branches (AVX-512: one compare mask per pixel and
//    block of partners, 16-bit lanes when coordinates fit, two pixels per step on short rows), and
//    the R bins of the valid pairs are compress-stored into a buffer. The plain loop's
//    unpredictable "is dx inside [Dmin, Dmax]" branch is what makes it slow. Without AVX-512 a
//    branch-free scalar loop does the same.
//  * The buffer, filled by many rows, is histogrammed into four interleaved copies of the
//    accumulator row, so that consecutive increments of one bin do not wait on each other; the
//    copies are summed once per theta.
//  * With the mirror rule (Params::mirror_tolerance_deg) most pairs of a row are examined only to be
//    rejected: a pixel of orientation a can only pair with orientations within the tolerance of
//    2 theta - a. For the 32-bit loops, pixels are grouped by orientation bucket once per frame and
//    a stable counting sort keeps every row of Rot grouped, so the possible partners of a pixel
//    are one run of the row taken twice over, found through a table of where each bucket starts;
//    only those are checked (Params::mirror_sorted_rows). The 16-bit AVX-512 loops check up to 32
//    partners a step, and there whole rows measured faster than windows; with mirror_sorted_rows
//    they take a faster way to the same votes instead (KernelChoice::fast_mirror): a ranked row
//    sort (sort_rows_ranked: placing a pixel waits on no counter), the rule as one unsigned
//    compare, pair sums shifted in the histogram, and the last 16 pixels of a long row two a step.
// The accumulator is bit-identical to reference_vote() (tests compare them).
#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <thread>
#include <type_traits>

#if defined(__AVX512F__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC 12 false positive inside avx512fintrin.h
#include <immintrin.h>
#pragma GCC diagnostic pop
#endif

#include "nudge/symmetry/detector.hpp"
#include "quantise.hpp"

namespace nudge::symmetry {

using detail::Layout;
using detail::ThetaTable;

namespace {

// Band test and bin index for one pair, shared by the scalar path.
struct PairRule {
  int32_t dmin2;    // minimum |xq_a - xq_b|
  uint32_t span;    // dmax2 - dmin2: valid iff (|d| - dmin2) <= span, as unsigned
  int32_t offset;   // added to xq_a + xq_b (+2 to round, + skew shift); >> 2 gives the histogram index
};

// The branch-free scalar loop with the mirror rule on the orientations a[0..n) (wide rows only:
// large images with mirror-consistent pairs).
inline int row_pair_bins_mirror(const int32_t* x, const int16_t* a, int n, const PairRule& rule,
                                const detail::MirrorRule& mirror, int32_t* out) {
  int count = 0;
  for (int i = 0; i + 1 < n; ++i) {
    const int32_t xi = x[i];
    for (int j = i + 1; j < n; ++j) {
      const int32_t d = std::abs(x[j] - xi);
      out[count] = (xi + x[j] + rule.offset) >> 2;
      count += (static_cast<uint32_t>(d - rule.dmin2) <= rule.span) &
               (std::abs(static_cast<int>(detail::mirror_error(a[i], a[j], mirror.target))) <= mirror.tolerance);
    }
  }
  return count;
}

// The portable loop of row_pair_bins (Params::vector_kernels = false, or no AVX-512).
inline int row_pair_bins_scalar(const int32_t* x, int n, const PairRule& rule, int32_t* out) {
  int count = 0;
  for (int i = 0; i + 1 < n; ++i) {
    const int32_t xi = x[i];
    for (int j = i + 1; j < n; ++j) {  // branch-free: always store, advance only when valid
      const int32_t d = std::abs(x[j] - xi);
      out[count] = (xi + x[j] + rule.offset) >> 2;
      count += static_cast<uint32_t>(d - rule.dmin2) <= rule.span;
    }
  }
  return count;
}

// Writes the histogram index of every valid pair of the row x[0..n) to out; returns how many.
// out needs room for n (n - 1) / 2 + 16 entries.
inline int row_pair_bins(const int32_t* x, int n, const PairRule& rule, int32_t* out) {
  int count = 0;
#if defined(__AVX512F__) && defined(__AVX512VL__)
  if (n <= 8) {
    // Short rows (most of them): 256-bit vectors do the same work at twice the rate of 512-bit
    // ones on CPUs that split 512-bit operations.
    const __m256i dmin = _mm256_set1_epi32(rule.dmin2);
    const __m256i span = _mm256_set1_epi32(static_cast<int32_t>(rule.span));
    const __m256i offset = _mm256_set1_epi32(rule.offset);
    const __mmask8 row_lanes = static_cast<__mmask8>((1u << n) - 1);
    const __m256i xs = _mm256_maskz_loadu_epi32(row_lanes, x);
    for (int i = 0; i + 1 < n; ++i) {
      const __m256i xi = _mm256_set1_epi32(x[i]);
      const __mmask8 lanes = static_cast<__mmask8>(row_lanes & ~((2u << i) - 1));  // partners after i
      const __m256i d = _mm256_abs_epi32(_mm256_sub_epi32(xs, xi));
      const __mmask8 ok = _mm256_mask_cmple_epu32_mask(lanes, _mm256_sub_epi32(d, dmin), span);
      const __m256i bins = _mm256_srai_epi32(_mm256_add_epi32(xs, _mm256_add_epi32(xi, offset)), 2);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + count), _mm256_maskz_compress_epi32(ok, bins));
      count += __builtin_popcount(static_cast<unsigned>(ok));
    }
    return count;
  }
#endif
#if defined(__AVX512F__)
  const __m512i dmin = _mm512_set1_epi32(rule.dmin2);
  const __m512i span = _mm512_set1_epi32(static_cast<int32_t>(rule.span));
  const __m512i offset = _mm512_set1_epi32(rule.offset);
  for (int i = 0; i + 1 < n; ++i) {
    const __m512i xi = _mm512_set1_epi32(x[i]);
    const __m512i base = _mm512_add_epi32(xi, offset);
    for (int j = i + 1; j < n; j += 16) {
      const int left = n - j;
      const __mmask16 lanes = left >= 16 ? static_cast<__mmask16>(0xFFFF) : static_cast<__mmask16>((1u << left) - 1);
      const __m512i xj = _mm512_maskz_loadu_epi32(lanes, x + j);
      const __m512i d = _mm512_abs_epi32(_mm512_sub_epi32(xj, xi));
      const __mmask16 ok = _mm512_mask_cmple_epu32_mask(lanes, _mm512_sub_epi32(d, dmin), span);
      const __m512i bins = _mm512_srai_epi32(_mm512_add_epi32(xj, base), 2);
      _mm512_storeu_si512(out + count, _mm512_maskz_compress_epi32(ok, bins));
      count += __builtin_popcount(static_cast<unsigned>(ok));
    }
  }
#else
  count = row_pair_bins_scalar(x, n, rule, out);
#endif
  return count;
}

#if defined(__AVX512BW__) && defined(__AVX512VL__) && defined(__AVX512VBMI2__)
constexpr bool kHaveNarrowPath = true;
// The same as row_pair_bins with 16-bit lanes: one 256-bit vector holds a row of up to 16 pixels
// and one 512-bit vector a row of up to 32, so most rows need a single compare per pixel. Only
// valid when every coordinate, difference and histogram index fits in int16 (see narrow_fits).
// With kMirror, a[0..n) are the row's orientations and pairs must also pass the mirror rule.
// With kFast (the mirror rule's fast path, Params::mirror_sorted_rows), two vector operations fewer
// per step: the rule is tested as one unsigned compare, (a_i + a_j - 2 theta + tol) mod 2^16 <=
// 2 tol, which is |a_i + a_j - 2 theta| <= tol without the absolute value; and out receives the
// pair sums x_i + x_j + offset unshifted (the histogram shifts them, add_votes' shift = 2).
template <bool kMirror, bool kFast = false>
inline int row_pair_bins16(const int16_t* x, const int16_t* a, int n, const PairRule& rule,
                           const detail::MirrorRule& mirror, int16_t* out) {
  static_assert(kMirror || !kFast, "the fast path is the mirror rule's");
  int count = 0;
  const int16_t dmin2 = static_cast<int16_t>(rule.dmin2);
  const int16_t span = static_cast<int16_t>(std::min<uint32_t>(rule.span, 0xFFFF));
  const int16_t offset = static_cast<int16_t>(rule.offset);
  // kFast: the pixel's side carries + tol, and the bound is 2 tol (<= 65534: tol <= 32767).
  const int16_t bias = kFast ? mirror.tolerance : int16_t{0};
  const __m512i vtol = _mm512_set1_epi16(kFast ? static_cast<int16_t>(2 * mirror.tolerance) : mirror.tolerance);
  // With kMirror: keeps the pairs whose |a_i + a_j - 2 theta| (int16 wraps modulo 180 deg) is
  // within the tolerance. ai_minus_target is a_i - 2 theta (+ tol with kFast).
  auto mirror_ok = [&](__mmask32 ok, __m512i aj, __m512i ai_minus_target) {
    const __m512i error = _mm512_add_epi16(aj, ai_minus_target);
    return _mm512_mask_cmple_epu16_mask(ok, kFast ? error : _mm512_abs_epi16(error), vtol);
  };
  auto bins_of = [](__m512i sums) { return kFast ? sums : _mm512_srai_epi16(sums, 2); };
  if (n <= 16) {
    // Two pixels per step: the row sits in both 256-bit halves of one 512-bit vector, the low
    // half compared with x[i] and the high half with x[i + 1].
    const uint32_t row_lanes = (1u << n) - 1;
    const __m512i xs = _mm512_broadcast_i64x4(_mm256_maskz_loadu_epi16(static_cast<__mmask16>(row_lanes), x));
    const __m512i vdmin = _mm512_set1_epi16(dmin2), vspan = _mm512_set1_epi16(span);
    __m512i as = _mm512_setzero_si512();
    if constexpr (kMirror) as = _mm512_broadcast_i64x4(_mm256_maskz_loadu_epi16(static_cast<__mmask16>(row_lanes), a));
    for (int i = 0; i + 1 < n; i += 2) {
      const int16_t next = i + 1 < n ? x[i + 1] : x[i];
      const __m512i xi = _mm512_inserti64x4(_mm512_castsi256_si512(_mm256_set1_epi16(x[i])), _mm256_set1_epi16(next), 1);
      const __m512i base = _mm512_inserti64x4(_mm512_castsi256_si512(_mm256_set1_epi16(static_cast<int16_t>(x[i] + offset))),
                                              _mm256_set1_epi16(static_cast<int16_t>(next + offset)), 1);
      const uint32_t after_i = row_lanes & ~((2u << i) - 1);
      const uint32_t after_next = i + 1 < n ? row_lanes & ~((4u << i) - 1) : 0;
      const __mmask32 lanes = static_cast<__mmask32>(after_i | (after_next << 16));
      const __m512i d = _mm512_abs_epi16(_mm512_sub_epi16(xs, xi));
      __mmask32 ok = _mm512_mask_cmple_epu16_mask(lanes, _mm512_sub_epi16(d, vdmin), vspan);
      if constexpr (kMirror) {
        const int16_t a_next = i + 1 < n ? a[i + 1] : a[i];
        const __m512i ai = _mm512_inserti64x4(
            _mm512_castsi256_si512(_mm256_set1_epi16(static_cast<int16_t>(a[i] - mirror.target + bias))),
            _mm256_set1_epi16(static_cast<int16_t>(a_next - mirror.target + bias)), 1);
        ok = mirror_ok(ok, as, ai);
      }
      const __m512i bins = bins_of(_mm512_add_epi16(xs, base));
      _mm512_storeu_si512(out + count, _mm512_maskz_compress_epi16(ok, bins));
      count += __builtin_popcount(static_cast<unsigned>(ok));
    }
    return count;
  }
  const __m512i vdmin = _mm512_set1_epi16(dmin2), vspan = _mm512_set1_epi16(span);
  // kFast: the last 16 pixels have at most 15 later partners each, a 32-lane step apiece; paired
  // up as a row of their own they take two pixels a step. The pixels before them still check
  // every later partner, the 16 included.
  constexpr int kTail = 16;
  const int wide_end = kFast ? n - kTail : n - 1;
  if constexpr (kFast) count = row_pair_bins16<kMirror, kFast>(x + wide_end, a + wide_end, kTail, rule, mirror, out);
  const __m512i voffset = _mm512_set1_epi16(offset);
  for (int i = 0; i < wide_end; ++i) {
    const __m512i xi = _mm512_set1_epi16(x[i]);
    // kFast: one broadcast fewer (an add instead, which more ports take).
    const __m512i base = kFast ? _mm512_add_epi16(xi, voffset) : _mm512_set1_epi16(static_cast<int16_t>(x[i] + offset));
    const __m512i ai = _mm512_set1_epi16(kMirror ? static_cast<int16_t>(a[i] - mirror.target + bias) : int16_t{0});
    for (int j = i + 1; j < n; j += 32) {
      const int left = n - j;
      const __mmask32 lanes = left >= 32 ? ~__mmask32{0} : static_cast<__mmask32>((1ull << left) - 1);
      // kFast: plain loads (a masked load costs a vector operation besides the load); x and a have
      // 32 readable entries past the row's end (sort_rows_ranked), and lanes past it are masked
      // out of both compares and of the compress.
      const __m512i xj = kFast ? _mm512_loadu_si512(x + j) : _mm512_maskz_loadu_epi16(lanes, x + j);
      const __m512i d = _mm512_abs_epi16(_mm512_sub_epi16(xj, xi));
      __mmask32 ok = _mm512_mask_cmple_epu16_mask(lanes, _mm512_sub_epi16(d, vdmin), vspan);
      if constexpr (kMirror)
        ok = mirror_ok(ok, kFast ? _mm512_loadu_si512(a + j) : _mm512_maskz_loadu_epi16(lanes, a + j), ai);
      const __m512i bins = bins_of(_mm512_add_epi16(xj, base));
      _mm512_storeu_si512(out + count, _mm512_maskz_compress_epi16(ok, bins));
      count += __builtin_popcount(static_cast<unsigned>(ok));
    }
  }
  return count;
}
#else
constexpr bool kHaveNarrowPath = false;
template <bool kMirror, bool kFast = false>
inline int row_pair_bins16(const int16_t*, const int16_t*, int, const PairRule&, const detail::MirrorRule&, int16_t*) {
  return 0;
}
#endif

// Rows grouped by orientation bucket (Params::mirror_sorted_rows). A pixel of orientation a can only pair
// with orientations in the window [S, S + 2 tol], S = 2 theta - tol - a (modulo 180 deg). The row is
// taken twice over (the second copy's orientations counting as raised by 180 deg), so that every
// window, even one that wraps past 180 deg, is one run [lo, hi) of the doubled row; index k of the
// doubled row is pixel k mod n. The runs come from a table of where each orientation bucket (the
// orientation's top bits) starts: a superset of the possible partners, since the exact distance
// and mirror tests still decide every pair.
constexpr int kAngleBucketBits = 6;
constexpr int kAngleBuckets = 1 << kAngleBucketBits;
constexpr int kAngleBucketShift = 16 - kAngleBucketBits;
// Shorter rows are checked whole: the table of bucket starts would cost more than it saves.
constexpr int kWindowedRowPixels = 8;

// starts[b], b = 0..2 kAngleBuckets: the first index of bucket b in the doubled row a[0..n),
// whose pixels are grouped by ascending bucket. Found from the back (no read-modify-write chain)
// and without branches: which buckets are empty is not predictable (with the branch the portable
// windowed voting measured 1.91x today's loops, without it 2.20x; docs/results/mirror_voting.md).
inline void bucket_starts(const int16_t* a, int n, int32_t* starts) {
  for (int b = 0; b <= kAngleBuckets; ++b) starts[b] = n;
  for (int k = n - 1; k >= 0; --k) starts[static_cast<uint16_t>(a[k]) >> kAngleBucketShift] = k;
  for (int b = kAngleBuckets - 1; b >= 0; --b)
    starts[b] = std::min(starts[b], starts[b + 1]);  // an empty bucket starts where the next one does
  for (int b = 0; b < kAngleBuckets; ++b) starts[kAngleBuckets + b] = n + starts[b];
  starts[2 * kAngleBuckets] = 2 * n;
}

// The run [lo, hi) of the doubled row that holds every possible later partner of pixel i, of
// orientation a: at most n long, so that no pixel appears twice, and starting after i (pixels
// k in [n, n + i] inside it are i's earlier ones again, skipped by the caller).
struct Window {
  int lo, hi;
};
inline Window mirror_window(int i, int16_t a, const detail::MirrorRule& mirror, const int32_t* starts, int n) {
  const int window_start = static_cast<uint16_t>(mirror.target - mirror.tolerance - a);
  const int lo = starts[window_start >> kAngleBucketShift];
  const int hi = starts[((window_start + 2 * mirror.tolerance) >> kAngleBucketShift) + 1];
  return {std::max(lo, i + 1), std::min(hi, lo + n)};
}

// The windowed pair check of the 32-bit loops: the same tests as row_pair_bins_mirror, on the
// partners in each pixel's window only. x and a are the doubled row (2n entries); index k is
// pixel k mod n, a later partner of i (each pair once) for k in (i, n) or (n + i, 2n).
inline int row_pair_bins_windowed(const int32_t* x, const int16_t* a, int n, const PairRule& rule,
                                  const detail::MirrorRule& mirror, const int32_t* starts, int32_t* out) {
  int count = 0;
  for (int i = 0; i + 1 < n; ++i) {
    const Window w = mirror_window(i, a[i], mirror, starts, n);
    const int32_t xi = x[i];
    auto check = [&](int k0, int k1) {
      for (int k = k0; k < k1; ++k) {  // branch-free: always store, advance only when valid
        const int32_t d = std::abs(x[k] - xi);
        out[count] = (xi + x[k] + rule.offset) >> 2;
        count += (static_cast<uint32_t>(d - rule.dmin2) <= rule.span) &
                 (std::abs(static_cast<int>(detail::mirror_error(a[i], a[k], mirror.target))) <= mirror.tolerance);
      }
    };
    check(w.lo, std::min(w.hi, n));
    check(std::max(w.lo, n + i + 1), w.hi);
  }
  return count;
}

// Skew offsets are whole quarter-pixels of the pair sum: R_skew = x'_mid - y' tan(phi).
inline int32_t skew_shift(int row, double tan_phi) {
  return static_cast<int32_t>(std::lround(-4.0 * row * tan_phi));
}

// Largest |tan(phi)| in the skew list, rounded up: sizes the margins of the histogram.
int skew_margin(const std::vector<double>& skew_deg) {
  double m = 0;
  for (double s : skew_deg) m = std::max(m, std::fabs(std::tan(s * M_PI / 180.0)));
  return static_cast<int>(std::ceil(m));
}

// Which pair loops a frame uses. 16-bit AVX-512 lanes (narrow) when coordinates, sums plus offsets
// and histogram indices all fit in int16; otherwise the 32-bit loops, where with the mirror rule
// rows grouped by orientation let each pixel check only its possible partners (windowed). The
// 16-bit loops check a whole row of up to 32 pixels in one step: there windows measured slower
// (docs/results/mirror_voting.md), so narrow rows are checked whole.
struct KernelChoice {
  int32_t offset;  // added to pair sums so that histogram indices are >= 0 for any skew
  bool narrow;
  bool windowed;
  bool fast_mirror;  // the mirror rule on the 16-bit loops: ranked row sort, row_pair_bins16<true, true>
};
KernelChoice choose_kernels(const Layout& layout, const Params& p) {
  KernelChoice c;
  c.offset = 4 * (layout.r_max + 2) * (1 + skew_margin(p.skew_deg));
  c.narrow = kHaveNarrowPath && p.vector_kernels && 4 * layout.r_max + 2 * c.offset + 16 < 32767;
  c.windowed = !c.narrow && p.mirror_tolerance_deg > 0 && p.mirror_sorted_rows;
  c.fast_mirror = c.narrow && p.mirror_tolerance_deg > 0 && p.mirror_sorted_rows;
  return c;
}

// The rotation of quantise.hpp for pixels given as (u2, v2) int16 pairs, 16 at a time with one
// 16-bit multiply-add per coordinate (u2 C + v2 S and v2 C - u2 S, exact in int32) instead of two
// 32-bit multiplies. Returns how many pixels it rotated (the rest are the caller's); 0 without
// AVX-512 BW.
size_t rotate_pairs16(const uint32_t* uv, size_t n, const ThetaTable& t, int row_max, int32_t* xq, int32_t* row) {
  size_t i = 0;
#if defined(__AVX512BW__)
  auto pair = [](int32_t low, int32_t high) {
    return _mm512_set1_epi32(static_cast<int32_t>(static_cast<uint32_t>(static_cast<uint16_t>(low)) |
                                                  static_cast<uint32_t>(static_cast<uint16_t>(high)) << 16));
  };
  const __m512i cos_sin = pair(t.c, t.s), minus_sin_cos = pair(-t.s, t.c);
  const __m512i half_x = _mm512_set1_epi32(1 << (detail::kFixedShift - 1));
  const __m512i half_row = _mm512_set1_epi32(1 << detail::kFixedShift), first_row = _mm512_set1_epi32(row_max);
  for (; i + 16 <= n; i += 16) {
    const __m512i p = _mm512_loadu_si512(uv + i);
    const __m512i x = _mm512_srai_epi32(_mm512_add_epi32(_mm512_madd_epi16(p, cos_sin), half_x), detail::kFixedShift);
    const __m512i y = _mm512_srai_epi32(_mm512_add_epi32(_mm512_madd_epi16(p, minus_sin_cos), half_row), detail::kFixedShift + 1);
    _mm512_storeu_si512(xq + i, x);
    _mm512_storeu_si512(row + i, _mm512_add_epi32(y, first_row));
  }
#else
  (void)uv, (void)n, (void)t, (void)row_max, (void)xq, (void)row;
#endif
  return i;
}

// Counting sort of the pixels into rows of Rot for the fast mirror path (KernelChoice::fast_mirror).
// The plain scatter increments a row's counter for every pixel it places, and pixels along an edge
// share rows, so each placement waits for the previous one's increment to reach memory. Here the
// counting pass notes each pixel's rank among the earlier pixels of its row (in its counter lane),
// so placing needs no counter update: slot = where the lane's part of the row starts + rank. x and
// angle travel as one 32-bit word (one store per pixel), split into the 16-bit arrays afterwards.
// Ranks fit in 16 bits: the 16-bit loops only run on images whose rows hold far fewer pixels.
// Writes starts[0..num_rows] and x16, angle16 in row order.
void sort_rows_ranked(const int32_t* xq, const int32_t* row, const int16_t* angle, size_t n, int num_rows,
                      std::vector<int32_t>& counts, std::vector<uint16_t>& rank, std::vector<uint32_t>& packed,
                      int32_t* starts, int16_t* x16, int16_t* angle16) {
  constexpr int kLanes = 4;  // pixel i counts in lane i % 4: four independent chains of increments
  counts.assign(kLanes * static_cast<size_t>(num_rows), 0);
  rank.resize(n);
  packed.resize(n);
  int32_t* c = counts.data();
  uint16_t* r = rank.data();
  size_t i = 0;
  for (; i + kLanes <= n; i += kLanes)
    for (int l = 0; l < kLanes; ++l) r[i + l] = static_cast<uint16_t>(c[l * num_rows + row[i + l]]++);
  for (; i < n; ++i) r[i] = static_cast<uint16_t>(c[row[i]]++);  // the tail counts in lane 0
  int32_t running = 0;
  for (int y = 0; y < num_rows; ++y) {
    starts[y] = running;
    for (int l = 0; l < kLanes; ++l) {
      const int32_t lane_count = c[l * num_rows + y];
      c[l * num_rows + y] = running;  // where lane l's pixels of row y start
      running += lane_count;
    }
  }
  starts[num_rows] = running;
  uint32_t* out = packed.data();
  auto word = [&](size_t p) {
    return static_cast<uint32_t>(static_cast<uint16_t>(xq[p])) | static_cast<uint32_t>(static_cast<uint16_t>(angle[p])) << 16;
  };
  i = 0;
  for (; i + kLanes <= n; i += kLanes)
    for (int l = 0; l < kLanes; ++l) out[c[l * num_rows + row[i + l]] + r[i + l]] = word(i + l);
  for (; i < n; ++i) out[c[row[i]] + r[i]] = word(i);
  for (size_t k = 0; k < n; ++k) {  // vectorised by the compiler
    x16[k] = static_cast<int16_t>(out[k] & 0xFFFF);
    angle16[k] = static_cast<int16_t>(out[k] >> 16);
  }
}

}  // namespace

namespace {

// The histogram index of a stored bin: the bin itself, or (kShift = 2) a non-negative pair sum >> 2.
template <int kShift, typename Bin>
inline auto histogram_index(Bin bin) {
  if constexpr (kShift == 0) return bin;
  else return static_cast<uint32_t>(static_cast<std::make_unsigned_t<Bin>>(bin)) >> kShift;
}

template <int kShift, typename Bin>
void histogram4(const Bin* bins, int votes, size_t hist_size, int32_t* h) {
  int q = 0;
  for (; q + 4 <= votes; q += 4) {
    ++h[histogram_index<kShift>(bins[q])];
    ++h[hist_size + histogram_index<kShift>(bins[q + 1])];
    ++h[2 * hist_size + histogram_index<kShift>(bins[q + 2])];
    ++h[3 * hist_size + histogram_index<kShift>(bins[q + 3])];
  }
  for (; q < votes; ++q) ++h[histogram_index<kShift>(bins[q])];
}

}  // namespace

// Histograms pair bins into the four interleaved copies of the accumulator row. Bins are
// histogram indices, or with shift = 2 pair sums (non-negative) whose index is sum >> 2.
template <typename Bin>
void Detector::add_votes(const Bin* bins, int votes, size_t hist_size, Scratch& s, int shift) const {
  if (shift == 2) histogram4<2>(bins, votes, hist_size, s.hist.data());
  else histogram4<0>(bins, votes, hist_size, s.hist.data());
}

// One row's bins under the rule "a row of Rot increments a bin at most once" (sec. 3.2.3).
template <typename Bin>
void Detector::add_votes_once(const Bin* bins, int votes, int32_t row_id, Scratch& s, int shift) const {
  int32_t* h = s.hist.data();
  for (int q = 0; q < votes; ++q) {
    const uint32_t b = shift == 2 ? histogram_index<2>(bins[q]) : static_cast<uint32_t>(bins[q]);
    if (s.stamp[b] == row_id) continue;
    s.stamp[b] = row_id;
    ++h[b];
  }
}

const Accumulator& Detector::vote(const EdgeSet& edges) {
  validate(params_);
  const Layout layout = detail::make_layout(edges.width, edges.height, params_);
  const int num_skews = 1 + static_cast<int>(params_.skew_deg.size());
  acc_.r_max = layout.r_max;
  acc_.votes.resize(num_skews);
  for (auto& m : acc_.votes) {
    m.create(kThetaBins, layout.num_r(), CV_32S);
    m.setTo(0);
  }
  const size_t n = edges.points.size();
  detail::require_mirror_angles(edges, params_);
  prepare_pixels(edges, choose_kernels(detail::make_layout(edges.width, edges.height, params_), params_).windowed);
  const std::vector<int> thetas = theta_bins_in_range(params_.theta_min_deg, params_.theta_max_deg);
  const int num_threads = std::max(1, std::min<int>(params_.threads, static_cast<int>(thetas.size())));
  scratch_.resize(num_threads);
  if (num_threads == 1 || n == 0) {
    vote_thetas(edges, thetas, 0, 1, scratch_[0]);
  } else {
    std::vector<std::thread> workers;
    for (int t = 1; t < num_threads; ++t) {
      workers.emplace_back([&, t] { vote_thetas(edges, thetas, t, num_threads, scratch_[t]); });
    }
    vote_thetas(edges, thetas, 0, num_threads, scratch_[0]);
    for (auto& w : workers) w.join();
  }
  return acc_;
}

// Edge pixels in doubled coordinates about the image centre, with their orientations: in the
// EdgeSet's order, or grouped by orientation bucket for windowed pair checks (a stable counting
// sort: within a bucket the pixels keep their order, so that pixels placed one after the other
// into rows of Rot land near each other).
void Detector::prepare_pixels(const EdgeSet& edges, bool group_by_orientation) {
  const size_t n = edges.points.size();
  const bool mirror = params_.mirror_tolerance_deg > 0;
  const std::vector<int16_t>& angles = detail::mirror_angles(edges, params_);  // orientations or directions
  u2_.resize(n);
  v2_.resize(n);
  angle_.assign(mirror ? n : 0, 0);
  std::vector<uint32_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = static_cast<uint32_t>(i);
  if (group_by_orientation) {
    auto bucket = [&](size_t i) { return static_cast<uint16_t>(angles[i]) >> kAngleBucketShift; };
    size_t next[kAngleBuckets + 1] = {};
    for (size_t i = 0; i < n; ++i) ++next[bucket(i) + 1];
    for (int b = 0; b < kAngleBuckets; ++b) next[b + 1] += next[b];
    for (size_t i = 0; i < n; ++i) order[next[bucket(i)]++] = static_cast<uint32_t>(i);
  }
  for (size_t k = 0; k < n; ++k) {
    const cv::Point p = edges.points[order[k]];
    u2_[k] = 2 * p.x - (edges.width - 1);
    v2_[k] = 2 * p.y - (edges.height - 1);
    if (mirror) angle_[k] = angles[order[k]];
  }
}

void Detector::vote_thetas(const EdgeSet& edges, const std::vector<int>& thetas, size_t first, size_t step,
                           Scratch& s) {
  const Layout layout = detail::make_layout(edges.width, edges.height, params_);
  const size_t n = u2_.size();
  const int num_rows = 2 * layout.row_max + 1;
  const int num_layers = static_cast<int>(acc_.votes.size());
  // Histogram index = (xq_a + xq_b + shift + offset + 2) >> 2; offset keeps it >= 0 for any skew.
  const KernelChoice kernels = choose_kernels(layout, params_);
  const int32_t offset = kernels.offset;
  const int index_of_bin0 = offset / 4 - layout.r_max;  // histogram index of R bin 0
  const size_t hist_size = static_cast<size_t>(2 * (offset / 4) + 8);
  constexpr int kCopies = 4;
  s.xq.resize(n);
  s.row.resize(n);
  s.sorted.resize(n);
  s.starts.resize(num_rows + 1);
  s.fill.resize(4 * static_cast<size_t>(num_rows));
  s.hist.assign(kCopies * hist_size, 0);
  s.stamp.assign(hist_size, -1);
  std::vector<double> tan_skew;
  for (double d : params_.skew_deg) tan_skew.push_back(std::tan(d * M_PI / 180.0));
  const PairRule base_rule{layout.dmin2, static_cast<uint32_t>(layout.dmax2 - layout.dmin2), offset + 2};
  const bool narrow = kernels.narrow;
  // The fast mirror loops read whole 32-lane vectors from a row's start: 32 entries of padding.
  const size_t padding = kernels.fast_mirror ? 32 : 0;
  if (narrow) s.sorted16.resize(n + padding);
  const bool mirror = params_.mirror_tolerance_deg > 0;
  const bool sorted_rows = kernels.windowed;  // rows of Rot keep the pixels' orientation grouping
  const int sum_shift = kernels.fast_mirror ? 2 : 0;  // the fast mirror loops store pair sums, not indices
  if (kernels.fast_mirror) {  // (u2, v2) as one word of two int16 (they fit: the 16-bit loops' images are small)
    s.uv.resize(n);
    for (size_t i = 0; i < n; ++i)
      s.uv[i] = static_cast<uint32_t>(static_cast<uint16_t>(u2_[i])) | static_cast<uint32_t>(static_cast<uint16_t>(v2_[i])) << 16;
  }
  if (mirror) s.angle16.resize(n + padding);
  s.bucket_start.resize(2 * kAngleBuckets + 1);

  for (size_t ti = first; ti < thetas.size(); ti += step) {
    const int k = thetas[ti];
    const ThetaTable t = detail::theta_table(k);
    // Rotate (vectorised), then a counting sort into rows of Rot with four interleaved sets of
    // counters: edge pixels come in runs along edges that fall into the same row, and one shared
    // counter per row would make every pixel wait for the previous one's increment.
    int32_t* xq = s.xq.data();
    int32_t* row = s.row.data();
    const int32_t* u = u2_.data();
    const int32_t* v = v2_.data();
    size_t rotated = 0;
    if (kernels.fast_mirror) rotated = rotate_pairs16(s.uv.data(), n, t, layout.row_max, xq, row);
    for (size_t i = rotated; i < n; ++i) {
      xq[i] = detail::rotated_xq(u[i], v[i], t);
      row[i] = detail::rotated_row(u[i], v[i], t) + layout.row_max;
    }
    if (kernels.fast_mirror) {
      sort_rows_ranked(xq, row, angle_.data(), n, num_rows, s.fill, s.rank, s.packed, s.starts.data(), s.sorted16.data(),
                       s.angle16.data());
    } else {
    constexpr int kLanes = 4;
    int32_t* counts = s.fill.data();  // kLanes x num_rows, lane-major
    int16_t* angle_out_sorted = s.angle16.data();
    std::fill(s.fill.begin(), s.fill.end(), 0);
    const size_t quarter = (n + kLanes - 1) / kLanes;  // grouped rows: lane l counts pixels [l quarter, (l + 1) quarter)
    const size_t last_quarter = n - std::min(n, (kLanes - 1) * quarter);
    if (sorted_rows) {
      size_t i = 0;
      for (; i < last_quarter; ++i)
        for (int l = 0; l < kLanes; ++l) ++counts[l * num_rows + row[l * quarter + i]];
      for (; i < quarter; ++i)
        for (int l = 0; l + 1 < kLanes; ++l)
          if (l * quarter + i < n) ++counts[l * num_rows + row[l * quarter + i]];
    } else {
      size_t i = 0;
      for (; i + kLanes <= n; i += kLanes)
        for (int l = 0; l < kLanes; ++l) ++counts[l * num_rows + row[i + l]];
      for (; i < n; ++i) ++counts[row[i]];
    }
    int32_t running = 0;
    for (int r = 0; r < num_rows; ++r) {
      s.starts[r] = running;
      for (int l = 0; l < kLanes; ++l) {
        const int32_t c = counts[l * num_rows + r];
        counts[l * num_rows + r] = running;  // becomes this lane's next free slot in row r
        running += c;
      }
    }
    s.starts[num_rows] = running;
    auto stable_scatter = [&](auto* out) {
      using Value = std::remove_pointer_t<decltype(out)>;
      auto place = [&](size_t src, int32_t& slot) {
        const int32_t dst = slot++;
        out[dst] = static_cast<Value>(xq[src]);
        angle_out_sorted[dst] = angle_[src];
      };
      size_t j = 0;
      for (; j < last_quarter; ++j)
        for (int l = 0; l < kLanes; ++l) place(l * quarter + j, counts[l * num_rows + row[l * quarter + j]]);
      for (; j < quarter; ++j)
        for (int l = 0; l + 1 < kLanes; ++l)
          if (l * quarter + j < n) place(l * quarter + j, counts[l * num_rows + row[l * quarter + j]]);
    };
    // With the mirror rule each pixel's orientation goes to the same place as its xq.
    const int16_t* orientation = angle_.data();
    int16_t* angle_out = s.angle16.data();
    auto scatter = [&](auto* out, auto with_angles) {
      using Value = std::remove_pointer_t<decltype(out)>;
      auto place = [&](size_t src, int32_t& slot) {
        const int32_t dst = slot++;
        out[dst] = static_cast<Value>(xq[src]);
        if constexpr (decltype(with_angles)::value) angle_out[dst] = orientation[src];
      };
      size_t j = 0;
      for (; j + kLanes <= n; j += kLanes)
        for (int l = 0; l < kLanes; ++l) place(j + l, counts[l * num_rows + row[j + l]]);
      for (; j < n; ++j) place(j, counts[row[j]]);
    };
    if (sorted_rows) {
      // Stable: lane l takes the l-th quarter of the (orientation-grouped) pixels, and its slots in
      // every row come after those of lanes < l, so each row stays grouped by orientation bucket.
      stable_scatter(s.sorted.data());
    } else if (narrow && mirror) scatter(s.sorted16.data(), std::true_type{});
    else if (narrow) scatter(s.sorted16.data(), std::false_type{});
    else if (mirror) scatter(s.sorted.data(), std::true_type{});
    else scatter(s.sorted.data(), std::false_type{});
    }
    const detail::MirrorRule mirror_rule = detail::mirror_rule(k, params_.mirror_tolerance_deg, params_.mirror_polarity);

    // A grouped row taken twice over (see row_pair_bins_windowed).
    auto doubled = [](const auto* row, int count, auto& buffer) {
      buffer.resize(2 * static_cast<size_t>(count));
      std::copy(row, row + count, buffer.begin());
      std::copy(row, row + count, buffer.begin() + count);
      return buffer.data();
    };
    auto starts_of = [&](const int16_t* angles, int count) {
      bucket_starts(angles, count, s.bucket_start.data());
      return s.bucket_start.data();
    };
    for (int layer = 0; layer < num_layers; ++layer) {
      const double tan_phi = layer == 0 ? 0.0 : tan_skew[layer - 1];
      size_t pending = 0;  // bins waiting in s.pairs / s.pairs16
      for (int r = 0; r < num_rows; ++r) {
        const int count = s.starts[r + 1] - s.starts[r];
        if (count < 2 || (params_.max_row_pixels > 0 && count > params_.max_row_pixels)) continue;
        PairRule rule = base_rule;
        if (layer > 0) rule.offset += skew_shift(r - layout.row_max, tan_phi);
        const size_t need = static_cast<size_t>(count) * (count - 1) / 2 + 32;
        // Bins of several rows are histogrammed together: reading them right after the vector
        // stores that wrote them would stall on store-to-load forwarding.
        if (narrow) {
          if (pending + need > s.pairs16.size()) {
            add_votes(s.pairs16.data(), static_cast<int>(pending), hist_size, s, sum_shift);
            pending = 0;
            if (need > s.pairs16.size()) s.pairs16.resize(std::max(need, size_t{16384}));
          }
          const int16_t* x16 = s.sorted16.data() + s.starts[r];
          int16_t* out16 = s.pairs16.data() + pending;
          const int16_t* a16 = mirror ? s.angle16.data() + s.starts[r] : nullptr;
          if (kernels.fast_mirror) pending += row_pair_bins16<true, true>(x16, a16, count, rule, mirror_rule, out16);
          else if (mirror) pending += row_pair_bins16<true>(x16, a16, count, rule, mirror_rule, out16);
          else pending += row_pair_bins16<false>(x16, nullptr, count, rule, mirror_rule, out16);
        } else {
          if (pending + need > s.pairs.size()) {
            add_votes(s.pairs.data(), static_cast<int>(pending), hist_size, s);
            pending = 0;
            if (need > s.pairs.size()) s.pairs.resize(std::max(need, size_t{16384}));
          }
          const int32_t* x32 = s.sorted.data() + s.starts[r];
          int32_t* out32 = s.pairs.data() + pending;
          // Orientations exist only with the mirror rule (no offset on an empty vector's null data).
          const int16_t* a16 = s.angle16.empty() ? nullptr : s.angle16.data() + s.starts[r];
          if (sorted_rows && count > kWindowedRowPixels)
            pending += row_pair_bins_windowed(doubled(x32, count, s.doubled_x), doubled(a16, count, s.doubled_angle),
                                              count, rule, mirror_rule, starts_of(a16, count), out32);
          else if (mirror)
            pending += row_pair_bins_mirror(x32, a16, count, rule, mirror_rule, out32);
          else
            pending += params_.vector_kernels ? row_pair_bins(x32, count, rule, out32)
                                              : row_pair_bins_scalar(x32, count, rule, out32);
        }
        if (params_.once_per_row) {  // the rule needs each row's bins on their own
          if (narrow) add_votes_once(s.pairs16.data(), static_cast<int>(pending), (k * num_layers + layer) * num_rows + r, s, sum_shift);
          else add_votes_once(s.pairs.data(), static_cast<int>(pending), (k * num_layers + layer) * num_rows + r, s);
          pending = 0;
        }
      }
      if (narrow) add_votes(s.pairs16.data(), static_cast<int>(pending), hist_size, s, sum_shift);
      else add_votes(s.pairs.data(), static_cast<int>(pending), hist_size, s);
      pending = 0;
      // Sum the copies into the accumulator row and clear them for the next theta.
      int32_t* out = acc_.votes[layer].ptr<int32_t>(k);
      int32_t* h = s.hist.data();
      for (int b = 0; b < layout.num_r(); ++b) {
        const size_t idx = static_cast<size_t>(index_of_bin0 + b);
        out[b] = h[idx] + h[hist_size + idx] + h[2 * hist_size + idx] + h[3 * hist_size + idx];
      }
      std::fill(s.hist.begin(), s.hist.end(), 0);
    }
  }
}

Accumulator reference_vote(const EdgeSet& edges, const Params& params) {
  validate(params);
  detail::require_mirror_angles(edges, params);
  const std::vector<int16_t>& angles = detail::mirror_angles(edges, params);
  const Layout layout = detail::make_layout(edges.width, edges.height, params);
  Accumulator acc;
  acc.r_max = layout.r_max;
  acc.votes.assign(1 + params.skew_deg.size(), cv::Mat());
  for (auto& m : acc.votes) m = cv::Mat::zeros(kThetaBins, layout.num_r(), CV_32S);
  for (int k : theta_bins_in_range(params.theta_min_deg, params.theta_max_deg)) {
    const ThetaTable t = detail::theta_table(k);
    // Rotate every edge pixel and group by row of Rot.
    struct Pixel {
      int32_t xq;
      int16_t orientation;
    };
    std::vector<std::vector<Pixel>> rows(2 * layout.row_max + 1);
    for (size_t i = 0; i < edges.points.size(); ++i) {
      const cv::Point p = edges.points[i];
      const int32_t u2 = 2 * p.x - (edges.width - 1), v2 = 2 * p.y - (edges.height - 1);
      const int16_t orientation = angles.empty() ? int16_t{0} : angles[i];
      rows[detail::rotated_row(u2, v2, t) + layout.row_max].push_back({detail::rotated_xq(u2, v2, t), orientation});
    }
    const detail::MirrorRule mirror = detail::mirror_rule(k, params.mirror_tolerance_deg, params.mirror_polarity);
    for (size_t sk = 0; sk < acc.votes.size(); ++sk) {
      const double tan_phi = sk == 0 ? 0.0 : std::tan(params.skew_deg[sk - 1] * M_PI / 180.0);
      int32_t* out = acc.votes[sk].ptr<int32_t>(k);
      for (size_t r = 0; r < rows.size(); ++r) {
        const auto& row = rows[r];
        if (params.max_row_pixels > 0 && static_cast<int>(row.size()) > params.max_row_pixels) continue;
        const int row_y = static_cast<int>(r) - layout.row_max;
        const int32_t shift = static_cast<int32_t>(std::lround(-4.0 * row_y * tan_phi));
        std::vector<char> voted(params.once_per_row ? layout.num_r() : 0, 0);
        // Every pair of the row, checked against [Dmin, Dmax].
        for (size_t i = 0; i < row.size(); ++i) {
          for (size_t j = i + 1; j < row.size(); ++j) {
            const int32_t dx = std::abs(row[i].xq - row[j].xq);
            if (dx < layout.dmin2 || dx > layout.dmax2) continue;
            if (!detail::mirror_consistent(row[i].orientation, row[j].orientation, mirror)) continue;
            const int b = layout.bin_of_sum(row[i].xq + row[j].xq + shift);
            if (b < 0 || b >= layout.num_r()) continue;
            if (params.once_per_row) {
              if (voted[b]) continue;
              voted[b] = 1;
            }
            ++out[b];
          }
        }
      }
    }
  }
  return acc;
}

}  // namespace nudge::symmetry
