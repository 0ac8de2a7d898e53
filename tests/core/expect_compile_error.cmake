# Compiles SOURCE twice with CXX and FLAGS (words separated by spaces): with
# -DPROXSEG_LIST_EVERY_MEMBER it must compile, without it it must fail with MESSAGE in the
# compiler's errors. Run by ctest:
#   cmake -DCXX=... -DFLAGS=... -DSOURCE=... -DMESSAGE=... -P expect_compile_error.cmake
separate_arguments(FLAGS UNIX_COMMAND "${FLAGS}")
execute_process(COMMAND ${CXX} ${FLAGS} -DPROXSEG_LIST_EVERY_MEMBER -fsyntax-only ${SOURCE}
                RESULT_VARIABLE good ERROR_VARIABLE good_errors)
if(NOT good EQUAL 0)
  message(FATAL_ERROR "${SOURCE} with every member listed does not compile:\n${good_errors}")
endif()
execute_process(COMMAND ${CXX} ${FLAGS} -fsyntax-only ${SOURCE}
                RESULT_VARIABLE bad ERROR_VARIABLE bad_errors)
if(bad EQUAL 0)
  message(FATAL_ERROR "${SOURCE} with a member left out of its adaptation compiles")
endif()
string(FIND "${bad_errors}" "${MESSAGE}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "${SOURCE} fails, but not with \"${MESSAGE}\":\n${bad_errors}")
endif()
message(STATUS "a member left out of its adaptation stops the build: \"${MESSAGE}\"")
