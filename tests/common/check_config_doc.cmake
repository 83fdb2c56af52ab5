# Fails when docs/configuration.md differs from what `auvrl config-doc` prints now.
#   cmake -DAUVRL=path/to/auvrl -DDOC=docs/configuration.md -P check_config_doc.cmake
execute_process(COMMAND ${AUVRL} config-doc OUTPUT_VARIABLE generated RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "auvrl config-doc failed (${rc})")
endif()
file(READ ${DOC} committed)
if(NOT generated STREQUAL committed)
  message(FATAL_ERROR "${DOC} is stale: regenerate it with\n"
                      "  build/bin/auvrl config-doc > docs/configuration.md\n"
                      "and commit it.")
endif()
