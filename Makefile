# Front door: `make demo` renders the default scene, `make test` runs every test.
# Both install missing Debian packages first (scripts/install-deps.sh), then
# configure and build Release in build/; quiet when everything is up to date.
BUILD ?= build
JOBS ?= $(shell nproc)
SCENE ?= scenes/room/room.json

.PHONY: deps scenes build demo test clean
# The packages first, whatever -j says: the scene generators need python3.
.NOTPARALLEL:

deps:
	@./scripts/install-deps.sh

# Generated scene data (not committed): the HDR sky, the gallery's spots and
# the light sets of the room at 10^3 to 10^5 lights (room_1e3/1e4/1e5.json).
ROOM_LIGHTS = scenes/room/lights_1e3.csv scenes/room/lights_1e4.csv scenes/room/lights_1e5.csv
scenes: deps scenes/sky/sky.exr scenes/gallery/spots_1e4.csv $(ROOM_LIGHTS)

LIGHTS_1e3 = 1000
LIGHTS_1e4 = 10000
LIGHTS_1e5 = 100000
scenes/room/lights_%.csv: scripts/gen_lights.py
	@python3 scripts/gen_lights.py --shape room --count $(LIGHTS_$*) --out $@

scenes/sky/sky.exr: scripts/make_sky.py
	@python3 scripts/make_sky.py >/dev/null

scenes/gallery/spots_1e4.csv: scripts/make_light_scenes.py
	@python3 scripts/make_light_scenes.py --spots 10000 --out $@

build: deps scenes
	@test -f $(BUILD)/Makefile || test -f $(BUILD)/build.ninja || cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release >/dev/null
	@cmake --build $(BUILD) -j $(JOBS) >$(BUILD)/build.log 2>&1 || { cat $(BUILD)/build.log; exit 1; }

demo: build
	@mkdir -p out
	@$(BUILD)/host/lightcuts render $(SCENE) -o out/room.exr --stats out/room-stats.json

test: build
	@cd $(BUILD) && LC_REQUIRE_VULKAN=1 ctest --output-on-failure --no-tests=error -j $(JOBS)

clean:
	@rm -rf $(BUILD) out
