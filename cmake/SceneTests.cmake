# One ctest per scene in scenes/, in two families, both run by plain `ctest`
# (so by ci/test.sh and .ci/run):
#   pov/NAME     label pov: `rayaudit compare`, our render against POV-Ray 3.7's,
#                judged by scenes/pov/NAME.json (default: identical at 8 bits);
#                a scene POV cannot express is a visible skip with its reason.
#   golden/NAME  label golden: `rayaudit golden check`, against golden/NAME.png;
#                on failure the diff image goes to BUILD/golden-diffs/.
file(GLOB RAYAUDIT_SCENES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/scenes/*.json)
set(RAYAUDIT_POV_OUT ${CMAKE_BINARY_DIR}/pov-compare)
file(MAKE_DIRECTORY ${RAYAUDIT_POV_OUT})
foreach(scene ${RAYAUDIT_SCENES})
  get_filename_component(name ${scene} NAME_WLE)
  add_test(NAME pov/${name}
           COMMAND rayaudit compare ${scene} --skip-inexpressible
                   --diff ${RAYAUDIT_POV_OUT}/${name}.diff.png --json ${RAYAUDIT_POV_OUT}/${name}.json)
  set_tests_properties(pov/${name} PROPERTIES LABELS pov SKIP_RETURN_CODE 77 TIMEOUT 300)
  add_test(NAME golden/${name}
           COMMAND rayaudit golden check ${name} --skip-unavailable --root ${PROJECT_SOURCE_DIR}
                   --diff-dir ${CMAKE_BINARY_DIR}/golden-diffs)
  set_tests_properties(golden/${name} PROPERTIES LABELS golden SKIP_RETURN_CODE 77 TIMEOUT 300)
endforeach()
