# Run by auvrl_lcm_types after lcm-gen (cmake -DFILES="a.hpp;b.hpp" -P LcmBoundLengths.cmake).
# lcm-gen 1.3.1's C++ decoder trusts two kinds of length field it reads from the wire:
# - Arrays: it sizes a variable-length array from its length field (vector::resize) before it
#   checks that the bytes are there, so a 60-byte message that claims 2^31 elements makes the
#   receiver allocate and zero gigabytes. This inserts, before each such resize, a refusal of a
#   length that is negative or larger than the bytes left: every array of our types carries at
#   least one byte per index, so a real message never trips it, and a decoder then allocates at
#   most a few times the message size.
# - Strings: it checks a string's length (characters plus the terminating NUL) only against the
#   bytes left, then copies length - 1 characters. A length of 0 or less made that copy throw,
#   and INT32_MIN wrapped to 2^31 - 1: one datagram made the receiver read 2 GB past its buffer.
#   This refuses a string length below one, which no encoder writes (a string field's
#   __NAME_len__, a string array element's __elem_len).
# Both were found by the fuzzers (tests/common/test_wire_limits.cpp).
set(marker "// auvrl: array and string lengths bounded by the bytes left (cmake/LcmBoundLengths.cmake)")
foreach(file ${FILES})
  file(READ ${file} text)
  string(FIND "${text}" "${marker}" found)
  if(NOT found EQUAL -1)
    continue()
  endif()
  string(REGEX REPLACE
    "\n([ ]*)(this->[A-Za-z0-9_]+[][a-z0-9]*)\\.resize\\((this->[A-Za-z0-9_]+)\\);"
    "\n\\1if (\\3 < 0 || \\3 > maxlen - pos) return -1;\n\\1\\2.resize(\\3);"
    text "${text}")
  string(REGEX REPLACE
    "if\\((__[A-Za-z0-9_]*len[A-Za-z0-9_]*) > maxlen - pos\\) return -1;"
    "if(\\1 < 1 || \\1 > maxlen - pos) return -1;"
    text "${text}")
  file(WRITE ${file} "${marker}\n${text}")
endforeach()
