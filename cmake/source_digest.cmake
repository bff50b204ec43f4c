# Writes OUT, a header defining lamina::kModelSourceDigest: the SHA-256 of the files listed in
# LIST (one path per line), names and contents. Run at build time (src/study/CMakeLists.txt) so
# that any edit of a model's code changes the study's model keys; OUT is rewritten only when the
# digest changes, so nothing else rebuilds.
file(STRINGS "${LIST}" files)
set(all "")
foreach(f IN LISTS files)
  file(SHA256 "${f}" h)
  file(RELATIVE_PATH rel "${ROOT}" "${f}")
  string(APPEND all "${rel} ${h}\n")
endforeach()
string(SHA256 digest "${all}")
string(SUBSTRING "${digest}" 0 16 digest)
set(text "#pragma once\n// Generated at build time by cmake/source_digest.cmake: the digest of the models' code\n// (src/core, src/physics, src/layers, src/randomwalk, src/models).\nnamespace lamina {\ninline constexpr const char* kModelSourceDigest = \"${digest}\";\n}  // namespace lamina\n")
if(EXISTS "${OUT}")
  file(READ "${OUT}" old)
  if(old STREQUAL text)
    return()
  endif()
endif()
file(WRITE "${OUT}" "${text}")
