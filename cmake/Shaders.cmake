# Compile every shaders/**/*.comp to SPIR-V at build time, validate it with spirv-val and
# embed it as a C array header in the build tree: shaders/<family>/<kernel>.comp becomes
# <build>/shaders/<family>/<kernel>_spv.h defining k<Family><Kernel>Spv. Sets
# MCD_KERNELS in the caller's scope: every kernel as <family>/<kernel>, sorted (the tests'
# kernel coverage is checked against it).
function(McdAddShaders target shaderDir)
  file(GLOB_RECURSE comps CONFIGURE_DEPENDS ${shaderDir}/*.comp)
  set(headers)
  set(kernels)
  foreach(comp ${comps})
    file(RELATIVE_PATH rel ${shaderDir} ${comp})
    string(REGEX REPLACE "\\.comp$" "" stem ${rel})
    list(APPEND kernels ${stem})
    string(REPLACE "/" "_" flat ${stem})
    set(spv ${CMAKE_BINARY_DIR}/shaders/${stem}.spv)
    set(hdr ${CMAKE_BINARY_DIR}/shaders/${stem}_spv.h)
    get_filename_component(hdrDir ${hdr} DIRECTORY)
    add_custom_command(
      OUTPUT ${hdr}
      COMMAND ${CMAKE_COMMAND} -E make_directory ${hdrDir}
      COMMAND ${GLSLANG_VALIDATOR} --quiet --target-env vulkan1.1 -I${shaderDir}
              -o ${spv} ${comp}
      COMMAND ${SPIRV_VAL} --target-env vulkan1.1 ${spv}
      COMMAND ${GLSLANG_VALIDATOR} --quiet --target-env vulkan1.1 -I${shaderDir}
              --vn k_${flat}_spv --depfile ${hdr}.d -o ${hdr} ${comp}
      DEPFILE ${hdr}.d
      DEPENDS ${comp}
      COMMENT "GLSL ${rel}"
      VERBATIM)
    list(APPEND headers ${hdr})
  endforeach()
  list(SORT kernels)
  set(MCD_KERNELS ${kernels} PARENT_SCOPE)
  add_custom_target(${target}_spv DEPENDS ${headers})
  add_library(${target} INTERFACE)
  add_dependencies(${target} ${target}_spv)
  target_include_directories(${target} INTERFACE ${CMAKE_BINARY_DIR}/shaders)
endfunction()
