# Turns a text file into a C++ translation unit defining
#   namespace antpose::embedded { extern const char* const SYMBOL; }
file(READ ${INPUT} content)
string(LENGTH "${content}" n)
set(chunks "")
set(pos 0)
# Raw string literals have a length limit in some compilers: emit ~8 kB pieces.
while(pos LESS n)
  string(SUBSTRING "${content}" ${pos} 8000 piece)
  string(APPEND chunks "R\"antpose_embed(${piece})antpose_embed\"\n")
  math(EXPR pos "${pos} + 8000")
endwhile()
file(WRITE ${OUTPUT} "// Generated from ${INPUT}; do not edit.\nnamespace antpose::embedded {\nextern const char* const ${SYMBOL};\nconst char* const ${SYMBOL} =\n${chunks};\n}\n")
