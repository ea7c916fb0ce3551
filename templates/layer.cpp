// Placeholder translation unit: the layer library needs one source while it grows.
namespace geode::templates {}
