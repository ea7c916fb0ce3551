// The user-facing exceptions keep their message one line of valid UTF-8 (primal/errors.hpp),
// whatever bytes of a file it quotes.
#include <doctest/doctest.h>

#include <string>

#include <geode/primal/errors.hpp>

using namespace geode;

TEST_CASE("errors: control characters and bytes that are not UTF-8 shown as \\xHH") {
  CHECK(std::string(InvalidInput("in.msh: line 3: 'ab'").what()) == "in.msh: line 3: 'ab'");
  // A newline and a NUL from a file, a lone continuation byte, a truncated sequence.
  CHECK(std::string(InvalidInput(std::string("a\nb\0c", 5)).what()) == "a\\x0ab\\x00c");
  CHECK(std::string(TopologyError("x \x80 y").what()) == "x \\x80 y");
  CHECK(std::string(InvalidInput("'-\xe2"
                                 "0'")
                        .what()) == "'-\\xe20'");
  // Valid UTF-8 (a block named in German, an emoji) is kept; overlong forms and surrogates are
  // not UTF-8.
  CHECK(std::string(InvalidInput("block 'St\xc3\xa4hl' \xf0\x9f\x94\xa9").what()) ==
        "block 'St\xc3\xa4hl' \xf0\x9f\x94\xa9");
  CHECK(std::string(InvalidInput("\xc0\xaf").what()) == "\\xc0\\xaf");
  CHECK(std::string(InvalidInput("\xed\xa0\x80").what()) == "\\xed\\xa0\\x80");
  CHECK(std::string(InvalidInput("\x7f\t").what()) == "\\x7f\\x09");
}
