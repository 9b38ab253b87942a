# fissure_target_defaults(<target>): warnings-as-errors and sanitizers for *our* code only
# (third-party headers come in as SYSTEM includes so their warnings do not fail our build).
function(fissure_target_defaults target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Werror -Wshadow -Wnon-virtual-dtor)
  if(FISSURE_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=${FISSURE_SANITIZE} -fno-omit-frame-pointer -fno-sanitize-recover=all)
    target_link_options(${target} PUBLIC -fsanitize=${FISSURE_SANITIZE})
  endif()
endfunction()

# fissure_host_header_library(<name> <dir under /usr/include>...): an INTERFACE target that
# gives a cross build the build machine's copy of an architecture-independent, header-only
# library (CLI11, toml++ in header-only mode). Only the named directories are exposed — through
# symlinks in the build tree — never /usr/include itself, whose C library headers belong to
# the build machine, not the target.
function(fissure_host_header_library name)
  set(root ${CMAKE_BINARY_DIR}/host-headers/${name})
  file(MAKE_DIRECTORY ${root})
  foreach(dir IN LISTS ARGN)
    if(NOT EXISTS /usr/include/${dir})
      message(FATAL_ERROR "${name}: /usr/include/${dir} is missing (toolchain/setup.sh installs it)")
    endif()
    file(CREATE_LINK /usr/include/${dir} ${root}/${dir} SYMBOLIC)
  endforeach()
  add_library(${name} INTERFACE)
  target_include_directories(${name} SYSTEM INTERFACE ${root})
endfunction()
