# OpenSubdiv oracle tools (included by the main Makefile; B = build dir).
# Notes: the main Makefile's phony `build` target has the same name as $(B), so an
# order-only `| $(B)` prerequisite would build the whole library; the recipes create the
# directory themselves instead. .DEFAULT_GOAL is saved/restored so that this fragment,
# included before `all:`, does not become the default goal.
ORACLE_SAVED_GOAL := $(.DEFAULT_GOAL)
ORACLE_CFLAGS      = -std=c11 -O2 -Wall -Wextra -Werror
ORACLE_CXXFLAGS    = -std=c++14 -O2 -Wall -Wextra -Werror

OSD_SHARED_SRC = tests/oracle/osd_limit.cpp tests/oracle/osd_obj.cpp
OSD_REFINE_SRC = tests/oracle/osd_refine.cpp tests/oracle/osd_patch.cpp $(OSD_SHARED_SRC)
$(B)/osd_refine: $(OSD_REFINE_SRC) tests/oracle/osd_oracle.h
	@mkdir -p $(@D)
	$(CXX) $(ORACLE_CXXFLAGS) $(OSD_REFINE_SRC) -o $@ -losdCPU

$(B)/objdiff: tests/oracle/objdiff.c
	@mkdir -p $(@D)
	$(CC) $(ORACLE_CFLAGS) $< -o $@ -lm

# fvar_oracle links the library too: ccnurbs' face-varying channels against OpenSubdiv in one
# process (tests/oracle/run_fvar_shapes.sh)
$(B)/fvar_oracle: tests/oracle/fvar_oracle.cpp $(OSD_SHARED_SRC) tests/oracle/osd_oracle.h $(B)/libccnurbs.a csrc/include/ccnurbs.h
	@mkdir -p $(@D)
	$(CXX) $(ORACLE_CXXFLAGS) -Icsrc/include tests/oracle/fvar_oracle.cpp $(OSD_SHARED_SRC) -o $@ $(B)/libccnurbs.a -losdCPU $(LDLIBS)

TEST_DEPS += $(B)/osd_refine $(B)/objdiff $(B)/fvar_oracle
DEPS_SCRIPTS += tests/oracle/osd_shapes_deps.sh
.DEFAULT_GOAL := $(ORACLE_SAVED_GOAL)
