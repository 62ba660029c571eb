# Quick start: `make demo` runs the main job on a built-in building; `make test` runs the tests.
# Both create .venv on first use: torch 2.13.0 (CPU) first, so the project's torch range
# installs nothing more, then the project with its dev, ROS 2 (rclpy, Fast DDS) and
# perception (OCR, GroundingDINO + SAM) extras, and Ray (--ray; its tests run in CI).

PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
OUT ?= out

.PHONY: setup demo test lint bench clean

setup: $(VENV)/.installed $(VENV)/.interfaces

$(VENV)/.installed: pyproject.toml
	test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet torch==2.13.0
	$(BIN)/pip install --quiet -e ".[dev,ros,ocr,gdino,ray]"
	# rapidocr's metadata names opencv-python; its other dependencies are the [ocr] extra.
	$(BIN)/pip install --quiet --no-deps rapidocr-onnxruntime==1.4.4
	touch $@

# The ROS 2 interface packages (Open-RMF's rmf_lift_msgs, the NavigateToRoom action, the
# Create 3's hazard messages), built with rosidl + ament_cmake from PyPI into the venv
# (~2 min). Needs cmake and a C++ compiler; without them pmnav-ros runs with its goal
# topics only and the action, hazard and lift tests are skipped.
$(VENV)/.interfaces: $(VENV)/.installed interfaces/build.sh $(wildcard interfaces/cmake/*.cmake interfaces/*/*.* interfaces/*/action/* interfaces/*/msg/*)
	interfaces/build.sh $(VENV) && touch $@ || echo "make: interface packages not built (see above); what needs them is unavailable"

demo: setup
	mkdir -p $(OUT)
	$(BIN)/pmnav map fig2_hospital --image $(OUT)/fig2_hospital_map.png > $(OUT)/fig2_hospital_map.txt
	$(BIN)/pmnav plan fig2_hospital --from seg13 --to "One-Stop Service Centre" \
		--image $(OUT)/fig2_hospital_plan.png > $(OUT)/fig2_hospital_plan.txt
	$(BIN)/pmnav sim run --building fig2_hospital --goal "One-Stop Service Centre" --out $(OUT)/run

lint: setup
	$(BIN)/ruff check .

test: lint
	$(BIN)/pytest -q

bench: setup
	$(BIN)/python benchmarks/bench_plan.py
	$(BIN)/python benchmarks/bench_sim.py
	$(BIN)/python benchmarks/bench_tree.py

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache .ruff_cache .hypothesis
