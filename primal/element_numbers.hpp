#pragma once
// The numbers a written file gives an all-hex model's hexes, so that messages and reports name a
// hex as the file does (docs/cli.md). Exodus numbers elements over its blocks in ascending id,
// each block's in model order, and geode's .msh writer tags them the same way (io/gmsh.hpp);
// VTK numbers cells in model order, from 0 as ParaView shows them. A model whose blocks do not
// come in ascending runs (a conform output: the diced hexes, then the templates' hexes, then
// the diced tets) is renumbered by the first two, so its indices are not its numbers there.
// (A mixed model differs between them: Exodus puts a block's other kinds in blocks of their
// own, numbered after every model block.)
#include <cstdint>
#include <span>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::primal {

enum class ElementOrder : std::uint8_t {
  kByBlock,  // blocks in ascending id, each in model order (Exodus, .msh)
  kAsGiven,  // model order (VTK)
};

struct ElementNumbering {
  ElementOrder order = ElementOrder::kByBlock;
  Index base = 1;  // the first element's number
};

// The numbers `numbering` gives the hexes `hexes` (indices, any order) of a model whose hex h is
// in block `block[h]`, in the order given: one pass over the blocks. Throws std::out_of_range
// for an index outside `block`.
std::vector<std::int64_t> hex_numbers(std::span<const int> block, std::span<const Index> hexes,
                                      ElementNumbering numbering);

}  // namespace geode::primal
