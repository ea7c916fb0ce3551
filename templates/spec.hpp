#pragma once
// Arrangements as files: a JSON spec of a domain and its sheets, read into the arrangement
// engine's sheets (stc::Sheet fields) and written back. The format is documented in README.md
// ("Arrangements as files"); in short:
//
//   {"dim": 3,
//    "domain": {"box": [[x0, y0, z0], [x1, y1, z1]]}  or {"hexahedron": [8 corners]} or {"pyramid":
//    [5]} "sheets": [{"name": "x", "plane": {"point": [..], "normal": [..]}},
//               {"name": "s", "sphere": {"center": [..], "radius": r}}, ...],
//    "completion": {"hex_side": {...}, "tet_side": {...}, "higher": "x"},   (optional)
//    "push": {"high_roof": .., "low_roof": .., "dome_depth": .., "dome_radius": ..},
//    "faces": {"bottom": {"points": [..], "cells": [..]}, "top": {...}},     (optional)
//    "sweep": {"push.high_roof": [0.55, 0.75], ...}}                         (study input)
//
// Shapes (each field negative inside, the completion builders' algebraic forms): plane, line,
// sphere, circle, ellipsoid, ellipse, cylinder, superquadric, tunnel, dome, and the field
// algebra of stc/sheet.hpp: union, intersection, offset, scaled. A completion block completes
// the dual of a diced interface into tunnels and domes (templates/completion.hpp) exactly as
// the built-in templates do; the built-ins are such specs (geode_spec in templates/geode.hpp).
//
// Every error is an InvalidInput "SOURCE: json.path: reason", e.g.
// "spec.json: sheets[2].sphere.radius: must be > 0".
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <geode/stc/arrangement.hpp>
#include <geode/templates/completion.hpp>
#include <geode/templates/geode.hpp>

namespace geode::templates {

// One sheet as given: its name, its report label ("kind", default the shape's name) and its
// shape, kept as the validated JSON object ({"sphere": {...}}) so that writing gives back
// what was read.
struct SheetSpec {
  std::string name;
  std::string kind;
  nlohmann::json shape;
};

// Tunnels and domes completed from a diced interface, pushed together by `push`: the hex
// side's cell on the domain's low-y face, the tet side's cells on its high-y face (physical
// coordinates, before dicing; 2D: segments on the low and high y edges). The domain must be
// a box; the builders work in its reference frame (templates/completion.hpp).
struct CompletionSpec {
  InterfacePatch hex_side;
  InterfacePatch tet_side;
  Higher higher = Higher::kX;
  PushParameters push;
};

struct ArrangementSpec {
  int dim = 3;
  stc::Domain domain;
  std::optional<CompletionSpec> completion;
  // Prescribed boundary faces without a completion (the "faces" block): cells on the box
  // domain's low-y ("bottom") and high-y ("top") face, quads in 3D, segments in 2D, taken as
  // they are (not diced). The dual must have exactly these cells there; their nodes are
  // placed at the given points (as a completion's diced nodes are).
  std::optional<InterfacePatch> bottom_face, top_face;
  std::vector<SheetSpec> sheets;  // after the completion's sheets
  nlohmann::json sweep;           // the "sweep" block as given (null when absent)
};

// Reads and validates; `source` names the spec in messages (usually its file name).
ArrangementSpec parse_spec(const nlohmann::json& spec, const std::string& source);
// A file: checked to be a JSON object of reasonable size before parsing.
nlohmann::json read_spec_json(const std::filesystem::path& path);
// The same for text in memory (`name` in messages): JSON with comments, nested at most 64
// levels (checked while parsing, before a deep tree is built), a JSON object.
nlohmann::json parse_spec_text(std::string_view text, const std::string& name);
ArrangementSpec read_spec(const std::filesystem::path& path);

// The spec as JSON (parse_spec(spec_json(s)) == s), and as text: objects one key a line,
// arrays of numbers on one line.
nlohmann::json spec_json(const ArrangementSpec& spec);
std::string format_spec(const nlohmann::json& spec);

// The arrangement's sheets: the completion's (tunnels, then domes) followed by the spec's own.
std::vector<stc::Sheet> spec_sheets(const ArrangementSpec& spec);

// ---- Sweeps (geode study interleave --spec) ------------------------------------------------

// One swept value: a path to a number in the spec ("push.high_roof", "sheets[1].sphere.radius")
// and the values it takes.
struct SweepAxis {
  std::string path;
  std::vector<double> values;
};
// "PATH=FROM:TO:COUNT" (COUNT evenly spaced values, ends included) or "PATH=V1,V2,...".
SweepAxis parse_sweep_option(const std::string& text);
// The spec's "sweep" block: {"PATH": [values] | {"from": a, "to": b, "count": n}}.
std::vector<SweepAxis> spec_sweep(const nlohmann::json& spec, const std::string& source);
// Sets the number at `path`; InvalidInput naming the path when it does not lead to a number.
void set_spec_number(nlohmann::json& spec, const std::string& path, double value,
                     const std::string& source);

}  // namespace geode::templates
