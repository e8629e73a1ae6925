# CCNURBS build. `make test` and `make demo` install what they need (deps) and build first.
CC      ?= cc
CXX     ?= c++
CFLAGS  ?= -O2 -g
WARN     = -std=c11 -Wall -Wextra -Werror -pedantic
CPPFLAGS = -Icsrc/include -Icsrc -D_POSIX_C_SOURCE=200809L
LDLIBS   = -llapacke -llapack -lm -lpthread
B        = build
# parallel jobs of the build inside `make test` (the reference machine has 2 cores)
TEST_JOBS ?= 2

# The library: every csrc/<layer>/*.c except the CLI (csrc/tools); csrc/README.md names the layers.
LIB_SRC  = $(sort $(filter-out csrc/tools/%,$(wildcard csrc/*/*.c)))
LIB_OBJ  = $(LIB_SRC:csrc/%.c=$(B)/obj/%.o)
PIC_OBJ  = $(LIB_SRC:csrc/%.c=$(B)/pic/%.o)
TEST_SRC = $(sort $(wildcard tests/c/test_*.c))
TEST_BIN = $(TEST_SRC:tests/c/%.c=$(B)/tests/%)
HDRS     = $(wildcard csrc/*/*.h tests/c/*.h)

APT_PKGS = build-essential clang libclang-rt-14-dev libosd-dev liblapacke-dev liblapack-dev \
           python3 python3-numpy zip curl xz-utils

.PHONY: all deps build test demo clean

all: build

# Each tests/*/NAME.mk may also append to DEPS_SCRIPTS: idempotent scripts run after the Debian
# packages are in (downloads they make are cached outside the checkout).
DEPS_SCRIPTS =

# Each tests/*/NAME.mk may add rules and append to TEST_DEPS (built before tests run).
TEST_DEPS =
-include $(wildcard tests/*/*.mk)


deps:
	@./tests/deps.sh $(APT_PKGS)
	@for s in $(DEPS_SCRIPTS); do sh $$s >/dev/null || exit 1; done

build: $(B)/libccnurbs.so $(B)/libccnurbs.a $(B)/ccnurbs

$(B)/obj/%.o: csrc/%.c $(HDRS)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -c $< -o $@
$(B)/pic/%.o: csrc/%.c $(HDRS)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -fPIC -c $< -o $@
$(B)/libccnurbs.a: $(LIB_OBJ)
	@rm -f $@
	ar rcs $@ $^
$(B)/libccnurbs.so: $(PIC_OBJ)
	$(CC) -shared -o $@ $^ $(LDLIBS)
$(B)/ccnurbs: $(wildcard csrc/tools/*.c) $(B)/libccnurbs.a $(HDRS)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $(wildcard csrc/tools/*.c) -o $@ $(B)/libccnurbs.a $(LDLIBS)

$(B)/tests/%: tests/c/%.c $(B)/libccnurbs.a $(HDRS)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) -Itests/c $(WARN) $(CFLAGS) $< -o $@ $(B)/libccnurbs.a $(LDLIBS)

test: deps
	@$(MAKE) --no-print-directory -j$(TEST_JOBS) build $(TEST_BIN) $(TEST_DEPS)
	@./tests/run_tests.sh

demo: deps
	@$(MAKE) --no-print-directory build
	@./tests/demo.sh

clean:
	rm -rf $(B) out
