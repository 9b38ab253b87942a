# fissure_target_defaults(<target>): warnings-as-errors and sanitizers for *our* code only
# (third-party headers come in as SYSTEM includes so their warnings do not fail our build).
function(fissure_target_defaults target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Werror -Wshadow -Wnon-virtual-dtor)
  if(FISSURE_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=${FISSURE_SANITIZE} -fno-omit-frame-pointer -fno-sanitize-recover=all)
    target_link_options(${target} PUBLIC -fsanitize=${FISSURE_SANITIZE})
  endif()
endfunction()
