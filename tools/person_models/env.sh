#!/usr/bin/env bash
# Creates (once) the Python virtual environment that `convert.py` runs in: the mediapipe wheel that
# holds the original TFLite person models, its TFLite runtimes (ai-edge-litert and mediapipe's own),
# tf2onnx with the TensorFlow it needs, onnx and onnxruntime to check the result, and scikit-image
# for the test pictures. tensorflow-cpu is 2.19 because mediapipe 0.10.21 wants protobuf < 5.
# Usage: source "$(dirname "$0")/env.sh"   (or run it, then use $PERSON_MODELS_VENV/bin/python)
# CI never needs this: the converted models and the fixtures are committed.
set -e
PERSON_MODELS_VENV=${PERSON_MODELS_VENV:-$HOME/.cache/mannequin-person-models}
if [ ! -x "$PERSON_MODELS_VENV/bin/python" ] || ! "$PERSON_MODELS_VENV/bin/python" -c "import mediapipe, tensorflow, tf2onnx, ai_edge_litert, onnx, onnxruntime, skimage, PIL" 2>/dev/null; then
  python3 -m venv "$PERSON_MODELS_VENV"
  "$PERSON_MODELS_VENV/bin/pip" install -q --upgrade pip
  "$PERSON_MODELS_VENV/bin/pip" install -q "mediapipe==0.10.21" "tensorflow-cpu==2.19.1" "tf2onnx==1.17.0" \
    "ai-edge-litert==2.3.0" "onnx==1.22.0" "onnxruntime==1.32.0" "numpy==1.26.4" "protobuf==4.25.9" \
    "pillow==13.0.0" "scikit-image==0.26.0"
fi
export PERSON_MODELS_VENV
echo "person-models python: $PERSON_MODELS_VENV/bin/python"
