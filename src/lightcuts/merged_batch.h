// The nodes of a merged cut (reconstruction.h) that need no shadow ray and hold omni or
// oriented lights, laid out as structure-of-arrays in blocks of four, so that the direct
// light of every pixel of a cell is summed over them four lanes at a time. This is where
// a reconstructed point spends its time: one contribution per node, and no shadow ray.
#pragma once

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "lightcuts/shading.h"
#include "core/light.h"

namespace lc::lightcuts {

using Float4 = float __attribute__((vector_size(16)));

struct MergedBatch {
  // Four nodes: node i is lane i % 4 of block i / 4; the last block is padded with nodes of
  // zero intensity. One block is one push per four nodes and 240 contiguous bytes (as
  // fifteen arrays of lanes, their pushes made add() 1.6x dearer: callgrind, 300k VPLs).
  struct Block {
    Float4 px, py, pz;           // representative's position
    Float4 nx, ny, nz;           // its normal (oriented lights); 0 for omni lights
    Float4 ir, ig, ib;           // the node's intensity (times its first-order factor)
    Float4 attA, attB, attC, attMax;  // attenuation min(1, 1/(a + b d + c d^2)), 0 beyond max
    Float4 oriented;             // 1: the light's cosine applies; 0: omni
    Float4 specular;             // 1: the group lights the specular term (not diffuseOnly)
  };
  std::vector<Block> blocks;
  size_t count = 0;
  bool anySpecular = false;

  void clear();
  void add(const Light& rep, const LightGroup& g, const Color& intensity);
};

// The unshadowed light at sp from the nodes of blocks [firstBlock, endBlock): the sum of
// lightContribution() times intensity, four lanes at a time (the specular power by a
// polynomial 2^(s log2 x), to float precision).
Color evaluateBatch(const MergedBatch& b, const ShadingPoint& sp, size_t firstBlock = 0, size_t endBlock = SIZE_MAX);

}  // namespace lc::lightcuts
