# Writes a C++ source holding INPUT's bytes as sampleTerrainBytes()/sampleTerrainSize().
file(READ "${INPUT}" hex HEX)
string(LENGTH "${hex}" hexLength)
math(EXPR size "${hexLength} / 2")
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
string(REGEX REPLACE "(0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,)" "\\1\n" bytes "${bytes}")
file(WRITE "${OUTPUT}.tmp" "// Generated from ${NAME}; do not edit.\n#include \"SampleTerrain.h\"\nnamespace terralux {\nnamespace {\nalignas(16) const unsigned char kBytes[${size}] = {\n${bytes}};\n}\nconst unsigned char* sampleTerrainBytes() { return kBytes; }\nsize_t sampleTerrainSize() { return ${size}; }\n}  // namespace terralux\n")
file(RENAME "${OUTPUT}.tmp" "${OUTPUT}")
