#pragma once
// The mesh isomorphism checker is a primal operation (primal/isomorphism.hpp; the Python module
// exposes it); the tests keep calling it by its geode::test names.
#include <geode/primal/isomorphism.hpp>

namespace geode::test {
using primal::find_isomorphism;
using primal::hex_symmetries;
using primal::is_isomorphism;
using primal::is_rotation;
using primal::MeshMapping;
using primal::NodeLabels;
using primal::quad_symmetries;
}  // namespace geode::test
