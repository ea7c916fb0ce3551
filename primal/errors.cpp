// Anchor translation unit so that every layer library has at least one source file.
#include <geode/primal/errors.hpp>
