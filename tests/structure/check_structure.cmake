# The architecture of core/, checked on every ctest run (issue 10):
#  1. each sub-folder of core/ opens with a README.md that says what it holds
#     and what it may depend on;
#  2. the dependency direction is one-way: a file in core/<folder>/ includes
#     only core/ folders listed for it below;
#  3. no file of core/ outside core/effects/ spells an effect of doc/contracts.md's
#     vocabulary as a string literal: generic code asks the effect's module
#     (core/effects/effect_module.h), it never tests a name.
# Run: cmake -DSOURCE_DIR=<repo> -P tests/structure/check_core_structure.cmake
if(NOT SOURCE_DIR)
  message(FATAL_ERROR "pass -DSOURCE_DIR=<repository root>")
endif()

set(folders common data physics effects model fit forecast synth diagnosis monitor)
# May depend on (besides itself).
set(allowed_common "")
set(allowed_data common)
set(allowed_physics common)
set(allowed_effects common physics)
set(allowed_model common physics effects)
set(allowed_fit common data physics effects model)
set(allowed_forecast common data physics effects model fit)
set(allowed_synth common data physics effects model)
set(allowed_diagnosis common data physics effects model fit forecast synth monitor)
set(allowed_monitor common data physics effects model fit synth)

set(vocabulary capacitance second_node wind sky_radiation iam flow_dependent_u
  transport_delay pv_clipping shading soiling clock_offset irradiance_bias)

# Literal effect names that are not the effect: a contract spelled the same
# way (file, name, why).
set(exempt
  "core/common/params.cc|irradiance_bias"  # the params.json key of the pyranometer scale error k
)

set(problems "")
file(GLOB present LIST_DIRECTORIES true RELATIVE ${SOURCE_DIR}/core ${SOURCE_DIR}/core/*)
foreach(entry IN LISTS present)
  if(IS_DIRECTORY ${SOURCE_DIR}/core/${entry})
    list(FIND folders ${entry} known)
    if(known EQUAL -1)
      string(APPEND problems "core/${entry}/: a folder the layering check does not know; add it to tests/structure/check_core_structure.cmake\n")
    endif()
  endif()
endforeach()

foreach(folder IN LISTS folders)
  set(readme ${SOURCE_DIR}/core/${folder}/README.md)
  if(NOT EXISTS ${readme})
    string(APPEND problems "core/${folder}/README.md is missing\n")
  else()
    file(READ ${readme} text)
    if(NOT text MATCHES "May depend on")
      string(APPEND problems "core/${folder}/README.md does not say what it may depend on ('May depend on')\n")
    endif()
  endif()
  file(GLOB_RECURSE sources ${SOURCE_DIR}/core/${folder}/*.h ${SOURCE_DIR}/core/${folder}/*.cc)
  foreach(source IN LISTS sources)
    file(RELATIVE_PATH rel ${SOURCE_DIR} ${source})
    # One list item per line: ';' and brackets would split or join items.
    file(READ ${source} content)
    string(REPLACE ";" "," content "${content}")
    string(REPLACE "[" "(" content "${content}")
    string(REPLACE "]" ")" content "${content}")
    string(REPLACE "\\" "/" content "${content}")
    string(REPLACE "\n" ";" lines "${content}")
    foreach(line IN LISTS lines)
      if(line MATCHES "^#include \"core/([a-z_]+)/")
        set(dep ${CMAKE_MATCH_1})
        list(FIND allowed_${folder} ${dep} ok)
        if(NOT dep STREQUAL folder AND ok EQUAL -1)
          string(APPEND problems "${rel}: includes core/${dep}/, but core/${folder}/ may depend on: ${allowed_${folder}}\n")
        endif()
      endif()
      if(NOT folder STREQUAL "effects")
        # Code only: drop a // comment (good enough for this code base).
        string(REGEX REPLACE "//.*$" "" code "${line}")
        foreach(name IN LISTS vocabulary)
          string(FIND "${code}" "\"${name}\"" at)
          list(FIND exempt "${rel}|${name}" exempt_at)
          if(NOT at EQUAL -1 AND exempt_at EQUAL -1)
            string(APPEND problems "${rel}: names the effect \"${name}\"; ask its module (core/effects/) instead\n")
          endif()
        endforeach()
      endif()
    endforeach()
  endforeach()
endforeach()

if(problems)
  message(FATAL_ERROR "core/ structure:\n${problems}")
endif()
message(STATUS "core/ structure: ${folders} — layering, READMEs and effect names ok")
