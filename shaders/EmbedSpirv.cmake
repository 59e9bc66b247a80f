# Writes a C++ source defining `std::span<const uint32_t> NAME()` over a SPIR-V binary.
file(READ "${INPUT}" hex HEX)
string(LENGTH "${hex}" hexLength)
math(EXPR words "${hexLength} / 8")
# Little-endian bytes -> 32-bit words.
string(REGEX REPLACE "([0-9a-f][0-9a-f])([0-9a-f][0-9a-f])([0-9a-f][0-9a-f])([0-9a-f][0-9a-f])" "0x\\4\\3\\2\\1u," body "${hex}")
string(REGEX REPLACE "((0x[0-9a-f]+u,){8})" "\\1\n" body "${body}")
file(WRITE "${OUTPUT}.tmp" "// Generated from ${SOURCE} by glslangValidator; do not edit.\n#include \"ShaderBinaries.h\"\nnamespace terralux::shaders {\nnamespace {\nconst uint32_t kWords[${words}] = {\n${body}};\n}\nstd::span<const uint32_t> ${NAME}() { return kWords; }\n}  // namespace terralux::shaders\n")
file(RENAME "${OUTPUT}.tmp" "${OUTPUT}")
