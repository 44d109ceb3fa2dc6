# Writes the header that `fire --version` prints: the project's version and the commit of the checkout it was
# built from. Run at every build, so the commit is never stale; the header changes only when they do, so
# nothing recompiles otherwise.
execute_process(COMMAND git -C "${SOURCE_DIR}" describe --always --dirty --abbrev=12
                OUTPUT_VARIABLE commit OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE status)
if(NOT status EQUAL 0 OR commit STREQUAL "")
  set(commit "unknown (not built from a git checkout)")
endif()
file(WRITE "${OUTPUT}.new" "#pragma once\n#define FIRE_VERSION \"${VERSION}\"\n#define FIRE_COMMIT \"${commit}\"\n")
file(COPY_FILE "${OUTPUT}.new" "${OUTPUT}" ONLY_IF_DIFFERENT)
file(REMOVE "${OUTPUT}.new")
