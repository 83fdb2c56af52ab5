# Generates C++ headers (and, where a JDK is present, a Java jar for lcm-spy) from .lcm files.
# LCM 1.3.1 on Debian ships no CMake package, so lcm-gen runs in custom commands.
#
#   auvrl_lcm_types(TARGET name PACKAGE pkg FILES a.lcm b.lcm ... [JAR jarname])
# defines an INTERFACE target `name` whose include directory holds pkg/<type>.hpp, and a target
# `name_jar` that builds ${CMAKE_BINARY_DIR}/share/java/<jarname>.jar.
function(auvrl_lcm_types)
  cmake_parse_arguments(ARG "" "TARGET;PACKAGE;JAR" "FILES" ${ARGN})
  set(gen_dir ${CMAKE_CURRENT_BINARY_DIR}/gen)
  set(hpp_files)
  set(java_files)
  foreach(lcm_file ${ARG_FILES})
    get_filename_component(type_name ${lcm_file} NAME_WE)
    get_filename_component(lcm_abs ${lcm_file} ABSOLUTE)
    list(APPEND lcm_abs_files ${lcm_abs})
    list(APPEND hpp_files ${gen_dir}/cpp/${ARG_PACKAGE}/${type_name}.hpp)
    list(APPEND java_files ${gen_dir}/java/${ARG_PACKAGE}/${type_name}.java)
  endforeach()

  add_custom_command(
    OUTPUT ${hpp_files}
    COMMAND ${LCM_GEN} --cpp --cpp-hpath ${gen_dir}/cpp ${lcm_abs_files}
    # Refuse array and string lengths the bytes cannot hold (see the script).
    COMMAND ${CMAKE_COMMAND} "-DFILES=${hpp_files}" -P ${PROJECT_SOURCE_DIR}/cmake/LcmBoundLengths.cmake
    DEPENDS ${lcm_abs_files} ${PROJECT_SOURCE_DIR}/cmake/LcmBoundLengths.cmake
    COMMENT "lcm-gen --cpp: ${ARG_PACKAGE}"
    VERBATIM)
  add_custom_target(${ARG_TARGET}_gen DEPENDS ${hpp_files})
  add_library(${ARG_TARGET} INTERFACE)
  add_dependencies(${ARG_TARGET} ${ARG_TARGET}_gen)
  # SYSTEM: lcm-gen 1.3.1's C++ for nested struct members fails -Wpedantic; not our code.
  target_include_directories(${ARG_TARGET} SYSTEM INTERFACE ${gen_dir}/cpp)

  set(lcm_jar /usr/share/java/lcm.jar)
  if(ARG_JAR AND Java_JAVAC_EXECUTABLE AND Java_JAR_EXECUTABLE AND EXISTS ${lcm_jar})
    set(jar_file ${CMAKE_BINARY_DIR}/share/java/${ARG_JAR}.jar)
    set(class_dir ${gen_dir}/classes)
    add_custom_command(
      OUTPUT ${jar_file}
      COMMAND ${CMAKE_COMMAND} -E rm -rf ${gen_dir}/java ${class_dir}
      COMMAND ${LCM_GEN} --java --jpath ${gen_dir}/java ${lcm_abs_files}
      COMMAND ${Java_JAVAC_EXECUTABLE} -nowarn -cp ${lcm_jar} -d ${class_dir} ${java_files}
      COMMAND ${CMAKE_COMMAND} -E make_directory ${CMAKE_BINARY_DIR}/share/java
      COMMAND ${Java_JAR_EXECUTABLE} cf ${jar_file} -C ${class_dir} .
      DEPENDS ${lcm_abs_files}
      COMMENT "lcm-gen --java and jar: ${ARG_JAR}.jar (for lcm-spy)"
      VERBATIM)
    add_custom_target(${ARG_TARGET}_jar ALL DEPENDS ${jar_file})
  elseif(ARG_JAR)
    message(WARNING "No JDK or /usr/share/java/lcm.jar: the lcm-spy types jar is not built")
  endif()
endfunction()
