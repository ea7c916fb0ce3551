// numpy and JSON conversions of the Python module (python/arrays.hpp).
#include "python/arrays.hpp"

#include <cmath>
#include <limits>

namespace geode::python {

namespace {

template <class T>
py::array owned(std::vector<T>&& v, std::vector<py::ssize_t> shape, py::dtype dtype) {
  auto* heap = new std::vector<T>(std::move(v));
  py::capsule owner(heap, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array(dtype, shape, heap->data(), owner);
}

}  // namespace

std::vector<Point> to_points(const py::handle& object, const std::string& what, bool finite) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(object);
  if (!a || a.ndim() != 2 || (a.shape(1) != 3 && a.shape(1) != 2))
    throw InvalidInput(what + ": expected an N x 3 (or N x 2) array of coordinates");
  const auto r = a.unchecked<2>();
  const bool planar = a.shape(1) == 2;
  std::vector<Point> points(primal::index_cast<std::size_t>(a.shape(0)));
  for (py::ssize_t i = 0; i < a.shape(0); ++i) {
    const Point p(r(i, 0), r(i, 1), planar ? 0.0 : r(i, 2));
    // Every measure of a cell at such a point is NaN or infinite: quality would report it.
    if (finite && !p.allFinite())
      throw InvalidInput(what + ": point " + std::to_string(i) + " (" + std::to_string(p.x()) +
                         ", " + std::to_string(p.y()) + ", " + std::to_string(p.z()) +
                         ") is not finite");
    points[primal::index_cast<std::size_t>(i)] = p;
  }
  return points;
}

int cell_width(const py::handle& object, const std::string& what) {
  const py::array a = py::array::ensure(object);
  if (!a || a.ndim() != 2 || (a.shape(1) != 4 && a.shape(1) != 8))
    throw InvalidInput(what + ": expected an M x 8 (hexes) or M x 4 (quads) array of node numbers");
  return static_cast<int>(a.shape(1));
}

template <int K>
std::vector<std::array<Index, K>> to_cells(const py::handle& object, const std::string& what,
                                           const std::function<std::string(std::size_t)>& cell) {
  const py::array any = py::array::ensure(object);
  if (any && any.size() > 0 && any.dtype().kind() != 'i' && any.dtype().kind() != 'u')
    throw InvalidInput(what + ": node numbers must be integers");
  const auto a =
      py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(object);
  if (!a || a.ndim() != 2 || a.shape(1) != K)
    throw InvalidInput(what + ": expected an M x " + std::to_string(K) + " array of node numbers");
  const auto r = a.unchecked<2>();
  // Unsigned 64-bit numbers past int64's range wrapped when cast: read as they were given.
  const bool wide_unsigned = any && any.dtype().kind() == 'u' && any.dtype().itemsize() == 8;
  const auto u =
      wide_unsigned
          ? py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>::ensure(object)
          : py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>();
  std::vector<std::array<Index, K>> cells(primal::index_cast<std::size_t>(a.shape(0)));
  for (py::ssize_t i = 0; i < a.shape(0); ++i)
    for (int c = 0; c < K; ++c) {
      const std::int64_t v = r(i, c);
      if (v < std::numeric_limits<Index>::min() || v > std::numeric_limits<Index>::max()) {
        const std::string given = wide_unsigned ? std::to_string(u.at(i, c)) : std::to_string(v);
        const auto at = primal::index_cast<std::size_t>(i);
        throw InvalidInput((cell ? cell(at) : what + ": cell " + std::to_string(at)) + ": corner " +
                           std::to_string(c + 1) + " refers to node index " + given +
                           ", outside the 32-bit index range");
      }
      cells[primal::index_cast<std::size_t>(i)][primal::index_cast<std::size_t>(c)] =
          primal::index_cast(v);
    }
  return cells;
}
template std::vector<std::array<Index, 4>> to_cells<4>(
    const py::handle&, const std::string&, const std::function<std::string(std::size_t)>&);
template std::vector<std::array<Index, 5>> to_cells<5>(
    const py::handle&, const std::string&, const std::function<std::string(std::size_t)>&);
template std::vector<std::array<Index, 6>> to_cells<6>(
    const py::handle&, const std::string&, const std::function<std::string(std::size_t)>&);
template std::vector<std::array<Index, 8>> to_cells<8>(
    const py::handle&, const std::string&, const std::function<std::string(std::size_t)>&);

py::array points_array(std::vector<Point>&& points) {
  const auto n = static_cast<py::ssize_t>(points.size());
  return owned(std::move(points), {n, 3}, py::dtype::of<double>());
}

template <int K>
py::array cells_array(std::vector<std::array<Index, K>>&& cells) {
  const auto n = static_cast<py::ssize_t>(cells.size());
  return owned(std::move(cells), {n, K}, py::dtype::of<Index>());
}
template py::array cells_array<4>(std::vector<std::array<Index, 4>>&&);
template py::array cells_array<5>(std::vector<std::array<Index, 5>>&&);
template py::array cells_array<6>(std::vector<std::array<Index, 6>>&&);
template py::array cells_array<8>(std::vector<std::array<Index, 8>>&&);

py::array index_array(std::vector<Index>&& values) {
  const auto n = static_cast<py::ssize_t>(values.size());
  return owned(std::move(values), {n}, py::dtype::of<Index>());
}

py::array double_array(std::vector<double>&& values) {
  const auto n = static_cast<py::ssize_t>(values.size());
  return owned(std::move(values), {n}, py::dtype::of<double>());
}

py::object to_python(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null:
      return py::none();
    case nlohmann::json::value_t::boolean:
      return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer:
      return py::int_(j.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned:
      return py::int_(j.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float:
      return py::float_(j.get<double>());
    case nlohmann::json::value_t::string:
      return py::str(j.get<std::string>());
    case nlohmann::json::value_t::array: {
      py::list l;
      for (const auto& x : j) l.append(to_python(x));
      return l;
    }
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (const auto& [k, v] : j.items()) d[py::str(k)] = to_python(v);
      return d;
    }
    default:
      return py::none();
  }
}

nlohmann::json to_json(const py::handle& o, const std::string& what) {
  if (o.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(o)) return o.cast<bool>();
  if (py::isinstance<py::int_>(o)) return o.cast<std::int64_t>();
  if (py::isinstance<py::float_>(o)) return o.cast<double>();
  if (py::isinstance<py::str>(o)) return o.cast<std::string>();
  if (py::isinstance<py::dict>(o)) {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& [k, v] : o.cast<py::dict>()) {
      if (!py::isinstance<py::str>(k)) throw InvalidInput(what + ": keys must be strings");
      const std::string key = k.cast<std::string>();
      j[key] = to_json(v, what + "." + key);
    }
    return j;
  }
  if (py::isinstance<py::array>(o)) return to_json(o.attr("tolist")(), what);
  if (py::isinstance<py::list>(o) || py::isinstance<py::tuple>(o)) {
    nlohmann::json j = nlohmann::json::array();
    std::size_t i = 0;
    for (const auto& v : o) j.push_back(to_json(v, what + "[" + std::to_string(i++) + "]"));
    return j;
  }
  // numpy scalars and other numbers
  if (py::hasattr(o, "item")) return to_json(o.attr("item")(), what);
  throw InvalidInput(what + ": " + py::str(py::type::of(o).attr("__name__")).cast<std::string>() +
                     " is not a JSON value");
}

}  // namespace geode::python
