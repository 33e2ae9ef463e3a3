// The four-lane twin of lightContribution() (the tests hold the two paths to the same
// values): every value is computed and then selected, without
// branches. GCC's vector extensions give the lane arithmetic; square roots use SSE where
// there is SSE (every x86-64), one lane at a time elsewhere. Lanes are summed in a fixed
// order, so the result does not depend on anything but the inputs.
#include "lightcuts/merged_batch.h"

#include <algorithm>
#include <cmath>

#if defined(__SSE__)
#include <xmmintrin.h>
#endif

namespace lc::lightcuts {

namespace {

using Mask4 = int __attribute__((vector_size(16)));

inline Float4 splat(float v) { return Float4{v, v, v, v}; }

inline Float4 sqrt4(Float4 v) {
#if defined(__SSE__)
  return _mm_sqrt_ps(v);
#else
  return Float4{std::sqrt(v[0]), std::sqrt(v[1]), std::sqrt(v[2]), std::sqrt(v[3])};
#endif
}

inline Float4 select(Mask4 m, Float4 a, Float4 b) { return m ? a : b; }

// x^y for x >= 0 as 2^(y log2 x), both by polynomials (relative error about 1e-7, as
// std::pow in float); 0^y = 0 for y > 0 and x^0 = 1.
inline Float4 log2pos(Float4 x) {
  Mask4 bits = (Mask4)x;  // a vector cast reinterprets the bits
  Mask4 e = ((bits >> 23) & 0xff) - 127;
  Mask4 mbits = (bits & 0x7fffff) | 0x3f800000;
  Float4 m = (Float4)mbits;  // [1, 2)
  Mask4 big = m > splat(1.41421356f);
  m = select(big, m * splat(0.5f), m);
  e = e + (big & 1);
  // log m = 2 atanh(t), t = (m - 1) / (m + 1), |t| <= 0.172
  Float4 t = (m - splat(1)) / (m + splat(1)), t2 = t * t;
  Float4 p = splat(1.0f / 9) * t2 + splat(1.0f / 7);
  p = p * t2 + splat(1.0f / 5);
  p = p * t2 + splat(1.0f / 3);
  p = p * t2 + splat(1);
  Float4 ef = __builtin_convertvector(e, Float4);
  return ef + splat(2.0f / 0.69314718f) * t * p;
}

inline Float4 exp2clamped(Float4 y) {
  y = select(y < splat(-126), splat(-126), y);
  y = select(y > splat(127), splat(127), y);
  Float4 nf = y + splat(0.5f);
  Mask4 n = __builtin_convertvector(nf, Mask4);  // truncates: floor for y + 0.5 >= 0
  n = n - ((__builtin_convertvector(n, Float4) > nf) & 1);
  Float4 f = (y - __builtin_convertvector(n, Float4)) * splat(0.69314718f);  // |f| <= ln2 / 2
  Float4 p = splat(1.0f / 720) * f + splat(1.0f / 120);
  p = p * f + splat(1.0f / 24);
  p = p * f + splat(1.0f / 6);
  p = p * f + splat(0.5f);
  p = p * f + splat(1);
  p = p * f + splat(1);
  Mask4 sbits = (n + 127) << 23;
  return p * (Float4)sbits;
}

inline Float4 pow4(Float4 x, float y) {
  if (y == 0) return splat(1);
  Float4 r = exp2clamped(splat(y) * log2pos(select(x > splat(0), x, splat(1))));
  return select(x > splat(0), r, splat(0));
}

}  // namespace

void MergedBatch::clear() {
  blocks.clear();
  count = 0;
  anySpecular = false;
}

void MergedBatch::add(const Light& rep, const LightGroup& g, const Color& intensity) {
  const size_t block = count / 4, lane = count % 4;
  if (lane == 0) {
    // A new block, its lanes harmless until filled: lights at the origin of zero intensity.
    blocks.emplace_back().attMax = splat(kInf);  // zeroed in place, not copied
  }
  Block& b = blocks[block];
  const bool o = rep.type == LightType::Oriented;
  b.px[lane] = rep.position.x;
  b.py[lane] = rep.position.y;
  b.pz[lane] = rep.position.z;
  b.nx[lane] = o ? rep.direction.x : 0.0f;
  b.ny[lane] = o ? rep.direction.y : 0.0f;
  b.nz[lane] = o ? rep.direction.z : 0.0f;
  b.ir[lane] = intensity.x;
  b.ig[lane] = intensity.y;
  b.ib[lane] = intensity.z;
  b.attA[lane] = g.atten.constant;
  b.attB[lane] = g.atten.linear;
  b.attC[lane] = g.atten.quadratic;
  b.attMax[lane] = g.atten.maxDistance;
  b.oriented[lane] = o ? 1.0f : 0.0f;
  b.specular[lane] = g.diffuseOnly ? 0.0f : 1.0f;
  anySpecular |= !g.diffuseOnly;
  ++count;
}

Color evaluateBatch(const MergedBatch& b, const ShadingPoint& sp, size_t firstBlock, size_t endBlock) {
  const Float4 Px = splat(sp.p.x), Py = splat(sp.p.y), Pz = splat(sp.p.z);
  const Float4 Nx = splat(sp.n.x), Ny = splat(sp.n.y), Nz = splat(sp.n.z);
  const Float4 Rx = splat(sp.r.x), Ry = splat(sp.r.y), Rz = splat(sp.r.z);
  const Float4 zero = splat(0), one = splat(1);
  // The specular term (only for groups that light it): ks max(R.w, 0)^s, with s = 0
  // giving ks wherever the light reaches.
  const bool specular = sp.hasSpecular() && b.anySpecular;
  Float4 dr = zero, dg = zero, db = zero, sr = zero, sg = zero, sb = zero;
  endBlock = std::min(endBlock, b.blocks.size());
  for (size_t k = firstBlock; k < endBlock; ++k) {
    const MergedBatch::Block& B = b.blocks[k];
    const Float4 o = B.oriented;
    const Float4 dx = B.px - Px, dy = B.py - Py, dz = B.pz - Pz;
    const Float4 d2 = dx * dx + dy * dy + dz * dz;
    const Float4 inv = one / sqrt4(select(d2 > zero, d2, one));
    const Float4 dist = d2 * inv;
    const Float4 wx = dx * inv, wy = dy * inv, wz = dz * inv;
    const Float4 den = B.attA + dist * (B.attB + dist * B.attC);
    const Float4 A = select(dist > B.attMax, zero, select(den <= one, one, one / select(den <= one, one, den)));
    const Float4 cL = o * -(B.nx * wx + B.ny * wy + B.nz * wz) + (one - o);
    const Float4 cN = Nx * wx + Ny * wy + Nz * wz;
    const Mask4 lit = (d2 > zero) & (cN > zero) & (cL > zero) & (A > zero);
    const Float4 G = select(lit, cL * A, zero);
    const Float4 vd = cN * G;
    dr += vd * B.ir;
    dg += vd * B.ig;
    db += vd * B.ib;
    if (specular) {
      const Float4 cR = Rx * wx + Ry * wy + Rz * wz;
      const Float4 vs = B.specular * pow4(select(cR > zero, cR, zero), sp.shininess) * G;
      sr += vs * B.ir;
      sg += vs * B.ig;
      sb += vs * B.ib;
    }
  }
  auto sum = [](Float4 v) { return (v[0] + v[1]) + (v[2] + v[3]); };
  Color total = sp.kd * Color(sum(dr), sum(dg), sum(db));
  if (specular) total += sp.ks * Color(sum(sr), sum(sg), sum(sb));
  return total;
}

}  // namespace lc::lightcuts
