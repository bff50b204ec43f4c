# Writes OUT, a header defining lamina::NAME (a string): the SHA-256 of the files listed in LIST
# (one path per line), names and contents, truncated to 16 hex digits. Run at build time
# (src/study/CMakeLists.txt) so that any edit of the code a table depends on changes the study's
# keys (kModelSourceDigest: the models' code; kReferenceSourceDigest: the reference's, the particle
# kernels included); WHAT describes the files. OUT is rewritten only when the digest changes, so
# nothing else rebuilds.
file(STRINGS "${LIST}" files)
set(all "")
foreach(f IN LISTS files)
  file(SHA256 "${f}" h)
  file(RELATIVE_PATH rel "${ROOT}" "${f}")
  string(APPEND all "${rel} ${h}\n")
endforeach()
string(SHA256 digest "${all}")
string(SUBSTRING "${digest}" 0 16 digest)
set(text "#pragma once\n// Generated at build time by cmake/source_digest.cmake: the digest of ${WHAT}.\nnamespace lamina {\ninline constexpr const char* ${NAME} = \"${digest}\";\n}  // namespace lamina\n")
if(EXISTS "${OUT}")
  file(READ "${OUT}" old)
  if(old STREQUAL text)
    return()
  endif()
endif()
file(WRITE "${OUT}" "${text}")
