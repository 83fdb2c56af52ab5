# Run by auvrl_lcm_types after lcm-gen (cmake -DFILES="a.hpp;b.hpp" -P LcmBoundArrays.cmake).
# lcm-gen 1.3.1's C++ decoder sizes a variable-length array from the length field it has just
# read (vector::resize) before it checks that the bytes are there, so a 60-byte message that
# claims 2^31 elements makes the receiver allocate and zero gigabytes (found by the fuzzers).
# This inserts, before each such resize, a refusal of a length that is negative or larger than
# the bytes left: every array of our types carries at least one byte per index, so a real
# message never trips it, and a decoder then allocates at most a few times the message size.
set(marker "// auvrl: array lengths bounded by the bytes left (cmake/LcmBoundArrays.cmake)")
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
  file(WRITE ${file} "${marker}\n${text}")
endforeach()
