# Compiles GLSL to SPIR-V at build time and embeds it as a uint32_t array
# (glslangValidator --vn). Headers land in ${PROJECT_BINARY_DIR}/shaders.
# rthdist_add_shader appends the generated header to the variable named by out_list.
function(rthdist_add_shader out_list source)
  get_filename_component(name ${source} NAME)
  string(REGEX REPLACE "[^A-Za-z0-9]" "_" var "k_spv_${name}")
  set(out ${PROJECT_BINARY_DIR}/shaders/${name}.h)
  set(src ${CMAKE_CURRENT_SOURCE_DIR}/${source})
  add_custom_command(
    OUTPUT ${out}
    COMMAND ${GLSLANG_VALIDATOR} --quiet --target-env vulkan1.2 -I${PROJECT_SOURCE_DIR}/shaders
            -I${PROJECT_SOURCE_DIR}/shaders/shared --depfile ${out}.d --vn ${var} -o ${out} ${src}
    DEPENDS ${src}
    DEPFILE ${out}.d
    COMMENT "glslang ${name}"
    VERBATIM)
  set(${out_list} ${${out_list}} ${out} PARENT_SCOPE)
endfunction()
