# Writes OUT, the header that names the commit a build came from (#define TRIAXDEM_COMMIT, `git describe` of SRC),
# and only when that commit changed, so that a new commit recompiles one file. Run at every build (CMakeLists.txt,
# target triaxdem_commit): a binary names the sources it was built from, not the commit its build was configured at.
execute_process(COMMAND git -C ${SRC} describe --always --dirty --abbrev=10
                OUTPUT_VARIABLE commit OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(NOT commit)
  set(commit "unknown")
endif()
set(content "#pragma once\n#define TRIAXDEM_COMMIT \"${commit}\"\n")
set(old "")
if(EXISTS ${OUT})
  file(READ ${OUT} old)
endif()
if(NOT old STREQUAL content)
  file(WRITE ${OUT} "${content}")
endif()
