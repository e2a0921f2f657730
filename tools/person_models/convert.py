"""MediaPipe's pretrained person models (Apache-2.0), converted to ONNX for `tract-onnx`, and golden
fixtures made with the original TFLite models so the Rust tests hold the Rust runtime to them.

Why: Mannequin cannot download anything at run time, so the networks it runs ship in the repo, and
the only person models a registry package ships under a licence that allows it are the TFLite
files in the `mediapipe==0.10.21` wheel (the 1.x wheels hold none). tract cannot load those
TFLite files (no DEQUANTIZE, DENSIFY, RESIZE_BILINEAR, ...), but runs their ONNX form.

`models DIR` writes, from the installed wheel's `mediapipe/modules/`:

- `pose_detection.onnx` (input [1,224,224,3] in [-1,1]; `regressors` [1,2254,12], `scores`
  [1,2254,1] logits). Its weights are sparse fp16 (DENSIFY then DEQUANTIZE), which tf2onnx cannot
  read: the TFLite interpreter materialises them, a dense copy of the .tflite holds them as plain
  float32 buffers, and tf2onnx converts that copy.
- `pose_landmark_full.onnx` (input [1,256,256,3] in [0,1]; `landmarks` [1,195], `pose_flag`
  [1,1], `mask` [1,256,256,1] logits, `heatmaps` [1,64,64,39], `world_landmarks` [1,117]):
  tf2onnx as it is.
- `selfie_segmentation.onnx` (input [1,256,256,3] in [0,1]; `mask` [1,256,256,1], a probability):
  tf2onnx leaves MediaPipe's custom op `Convolution2DTransposeBias`, replaced here by ConvTranspose
  (kernel 2, stride 2, bias).
- `face_detection_short_range.onnx` (BlazeFace; input [1,128,128,3] in [-1,1]; `regressors`
  [1,896,16] = box and 6 keypoints, `scores` [1,896,1] logits) and `face_landmark.onnx` (input
  [1,192,192,3] in [0,1]; `landmarks` [1,1,1,1404] = 468 face-mesh points x, y, z in crop pixels,
  `face_flag` [1,1,1,1] logit): tf2onnx as they are.

All take NHWC float32 named `input`, fixed shapes, opset 17, float32 weights. Each is checked
(onnx checker, strict shape inference, onnxruntime against the original on the fixture pictures)
and `LICENSE` (the wheel's) and `NOTICE.md` (sources, sha256, changes) are written beside them.

`fixtures DIR` writes, for scikit-image's `astronaut` and `camera` (grey, channels repeated):
`landmark_<image>.npz`, `selfie_<image>.npz` (the picture resized to 256² with Pillow's
bilinear `Image.resize`, `input_u8` [256,256,3], fed as input_u8 / 255), `detection_<image>.npz`
(224², fed as input_u8 / 127.5 - 1), `face_detection_<image>.npz` (128², as the pose detector)
and `face_landmark_<image>.npz` (192², / 255) holding each original output under the ONNX names
(heatmaps left out: 640 kB of noise); `pipeline_<image>.npz`, MediaPipe's whole pose pipeline on
the 512² picture, the end-to-end oracle for the Rust detection -> crop -> landmark path; and
`face_pipeline_<image>.npz`, its face-mesh pipeline likewise.

The original runs: pose detection and landmarks in ai-edge-litert's interpreter without its
default XNNPACK delegate (which swallows the fp16 DEQUANTIZE outputs: every weight reads zero);
the selfie model, whose custom op only MediaPipe's runtime knows, in a MediaPipe graph with
MediaPipe's op resolver and the plain TFLite delegate.

Run: source tools/person_models/env.sh
     $PERSON_MODELS_VENV/bin/python tools/person_models/convert.py models crates/mannequin-fit/models
     $PERSON_MODELS_VENV/bin/python tools/person_models/convert.py fixtures crates/mannequin-fit/tests/data
"""
import hashlib
import importlib.metadata
import os
import shutil
import sys
import tempfile

import numpy as np
import onnx
import onnxruntime
from onnx import helper, numpy_helper
from PIL import Image

import mediapipe as mp
from ai_edge_litert.interpreter import Interpreter, OpResolverType

WHEEL = "mediapipe"
MODULES = os.path.join(mp.__path__[0], "modules")
DETECTION = "pose_detection/pose_detection.tflite"
LANDMARK = "pose_landmark/pose_landmark_full.tflite"
SELFIE = "selfie_segmentation/selfie_segmentation.tflite"
FACE_DETECTION = "face_detection/face_detection_short_range.tflite"
FACE_LANDMARK = "face_landmark/face_landmark.tflite"
# TFLite output order -> ONNX output names.
OUTPUT_NAMES = {
    DETECTION: ["regressors", "scores"],
    LANDMARK: ["landmarks", "pose_flag", "mask", "heatmaps", "world_landmarks"],
    SELFIE: ["mask"],
    FACE_DETECTION: ["regressors", "scores"],
    FACE_LANDMARK: ["landmarks", "face_flag"],
}
# Each model's input side and value range: (side, divisor, offset), fed pixel_u8 / divisor + offset.
INPUTS = {
    DETECTION: (224, 127.5, -1.0),
    LANDMARK: (256, 255, 0.0),
    SELFIE: (256, 255, 0.0),
    FACE_DETECTION: (128, 127.5, -1.0),
    FACE_LANDMARK: (192, 255, 0.0),
}
IMAGES = ["astronaut", "camera"]
OPSET = 17


# --- the original models ---------------------------------------------------------------------

def tflite_path(model):
    return os.path.join(MODULES, model)


def interpreter(path, keep_tensors=False):
    """ai-edge-litert without XNNPACK (which zeroes fp16 DEQUANTIZE outputs)."""
    it = Interpreter(model_path=path, experimental_preserve_all_tensors=keep_tensors,
                     experimental_op_resolver_type=OpResolverType.BUILTIN_WITHOUT_DEFAULT_DELEGATES)
    it.allocate_tensors()
    return it


def run_tflite(model, x):
    """The original model on x (NHWC float32), outputs under the ONNX names."""
    if model == SELFIE:
        return {"mask": run_selfie_mediapipe(x)}
    it = interpreter(tflite_path(model))
    it.set_tensor(it.get_input_details()[0]["index"], x)
    it.invoke()
    outs = [it.get_tensor(d["index"]) for d in it.get_output_details()]
    return dict(zip(OUTPUT_NAMES[model], outs))


SELFIE_GRAPH = """
input_stream: "image"
output_stream: "input_floats"
output_stream: "mask_floats"
node {
  calculator: "ImageToTensorCalculator"
  input_stream: "IMAGE:image"
  output_stream: "TENSORS:input_tensor"
  options { [mediapipe.ImageToTensorCalculatorOptions.ext] {
    output_tensor_width: 256 output_tensor_height: 256
    output_tensor_float_range { min: 0.0 max: 1.0 } } }
}
node {
  calculator: "TfLiteCustomOpResolverCalculator"
  output_side_packet: "OP_RESOLVER:op_resolver"
}
node {
  calculator: "InferenceCalculator"
  input_stream: "TENSORS:input_tensor"
  output_stream: "TENSORS:mask_tensor"
  input_side_packet: "OP_RESOLVER:op_resolver"
  options { [mediapipe.InferenceCalculatorOptions.ext] {
    model_path: "mediapipe/modules/selfie_segmentation/selfie_segmentation.tflite"
    delegate { tflite {} } } }
}
node {
  calculator: "TensorsToFloatsCalculator"
  input_stream: "TENSORS:input_tensor"
  output_stream: "FLOATS:input_floats"
}
node {
  calculator: "TensorsToFloatsCalculator"
  input_stream: "TENSORS:mask_tensor"
  output_stream: "FLOATS:mask_floats"
}
"""


def run_selfie_mediapipe(x):
    """The selfie model in MediaPipe's own runtime, the only one with its custom op. A 256² picture
    goes through ImageToTensor unscaled; the graph also returns the tensor it fed, to prove that."""
    from mediapipe.python._framework_bindings import resource_util
    resource_util.set_resource_dir(os.path.dirname(mp.__path__[0]))
    u8 = np.round(x[0] * 255).astype(np.uint8)
    assert np.array_equal(u8.astype(np.float32) / 255, x[0]), "selfie input must be u8 / 255"
    graph = mp.CalculatorGraph(graph_config=SELFIE_GRAPH)
    got = {}
    for name in ["input_floats", "mask_floats"]:
        graph.observe_output_stream(
            name, lambda s, p: got.__setitem__(s, np.array(mp.packet_getter.get_float_list(p), np.float32)))
    graph.start_run()
    frame = mp.packet_creator.create_image_frame(image_format=mp.ImageFormat.SRGB, data=u8)
    graph.add_packet_to_input_stream("image", frame.at(0))
    graph.close()
    fed = got["input_floats"].reshape(x.shape)
    assert np.abs(fed - x).max() < 1e-6, f"MediaPipe fed the selfie model {np.abs(fed - x).max()} off"
    return got["mask_floats"].reshape(1, 256, 256, 1)


# --- conversion ------------------------------------------------------------------------------

def tf2onnx_convert(path):
    import tf2onnx
    model, _ = tf2onnx.convert.from_tflite(path, opset=OPSET)
    return model


def dense_detection_tflite(out_path):
    """A copy of the pose detector with every DENSIFY/DEQUANTIZE weight chain replaced by the
    float32 constant the interpreter computes for it (fp16 -> f32 is exact)."""
    from tensorflow.lite.python import schema_py_generated as schema
    from tensorflow.lite.tools import flatbuffer_utils
    path = tflite_path(DETECTION)
    it = interpreter(path, keep_tensors=True)
    it.set_tensor(it.get_input_details()[0]["index"], np.zeros((1, 224, 224, 3), np.float32))
    it.invoke()
    model = flatbuffer_utils.read_model(path)
    graph = model.subgraphs[0]
    codes = [max(c.builtinCode, c.deprecatedBuiltinCode) for c in model.operatorCodes]
    weight_ops = (schema.BuiltinOperator.DENSIFY, schema.BuiltinOperator.DEQUANTIZE)
    made = {out for op in graph.operators if codes[op.opcodeIndex] in weight_ops for out in op.outputs}
    kept, zeros = [], 0
    for op in graph.operators:
        if codes[op.opcodeIndex] not in weight_ops:
            kept.append(op)
            continue
        assert all(i in made or model.buffers[graph.tensors[i].buffer].data is not None
                   for i in op.inputs), "a DEQUANTIZE of an activation"
        for i in op.inputs:  # the fp16 (maybe sparse) original, now unused: drop its data
            graph.tensors[i].buffer, graph.tensors[i].sparsity = 0, None
        if codes[op.opcodeIndex] == schema.BuiltinOperator.DEQUANTIZE:
            out = op.outputs[0]
            value = it.get_tensor(out).astype(np.float32)
            assert graph.tensors[out].type == schema.TensorType.FLOAT32
            zeros += not value.any()
            buffer = schema.BufferT()
            buffer.data = np.frombuffer(value.tobytes(), np.uint8)
            model.buffers.append(buffer)
            graph.tensors[out].buffer = len(model.buffers) - 1
    assert zeros < 10, f"{zeros} weights read as zero: is XNNPACK on?"  # 6 zero biases
    graph.operators = kept
    flatbuffer_utils.write_model(model, out_path)


def replace_transpose_conv_bias(model):
    """MediaPipe's Convolution2DTransposeBias (NHWC input, weights [out,kh,kw,in], bias [out]) as
    ConvTranspose (NCHW, weights [in,out,kh,kw]) between layout transposes. Kernel 2, stride 2:
    SAME and VALID both give twice the size, no padding."""
    graph = model.graph
    inits = {t.name: t for t in graph.initializer}
    producer = {o: n for n in graph.node for o in n.output}
    nodes = []
    for node in graph.node:
        if node.op_type != "TFL_Convolution2DTransposeBias":
            nodes.append(node)
            continue
        x, w, b = node.input
        weights = numpy_helper.to_array(inits[w])
        assert weights.shape[1:3] == (2, 2), weights.shape
        inits[w].CopyFrom(numpy_helper.from_array(weights.transpose(3, 0, 1, 2).copy(), w))
        into = producer[x]  # tf2onnx's NCHW -> NHWC transpose: take its input directly
        assert into.op_type == "Transpose" and list(into.attribute[0].ints) == [0, 2, 3, 1]
        nchw = node.output[0] + "_nchw"
        nodes.append(helper.make_node("ConvTranspose", [into.input[0], w, b], [nchw], name=node.name,
                                      kernel_shape=[2, 2], strides=[2, 2]))
        nodes.append(helper.make_node("Transpose", [nchw], [node.output[0]], name=node.name + "_nhwc",
                                      perm=[0, 2, 3, 1]))
    del graph.node[:]
    graph.node.extend(nodes)
    drop_dead_nodes(model)


def drop_dead_nodes(model):
    graph = model.graph
    needed = {o.name for o in graph.output}
    live = []
    for node in reversed(graph.node):
        if any(o in needed for o in node.output):
            live.append(node)
            needed.update(node.input)
    del graph.node[:]
    graph.node.extend(reversed(live))
    unused = [t for t in graph.initializer if t.name not in needed]
    for t in unused:
        graph.initializer.remove(t)


def rename(model, old, new):
    graph = model.graph
    for node in graph.node:
        node.input[:] = [new if i == old else i for i in node.input]
        node.output[:] = [new if o == old else o for o in node.output]
    for value in list(graph.input) + list(graph.output) + list(graph.value_info):
        if value.name == old:
            value.name = new


def tidy(model, tflite_model, source):
    """Descriptive input/output names, only the default opset, and where the file comes from."""
    it_in, it_out = tflite_input_output_names(tflite_model)
    assert [i.name for i in model.graph.input] == it_in, [i.name for i in model.graph.input]
    assert [o.name for o in model.graph.output] == it_out, [o.name for o in model.graph.output]
    rename(model, it_in[0], "input")
    for old, new in zip(it_out, OUTPUT_NAMES[tflite_model]):
        rename(model, old, new)
    del model.opset_import[:]
    model.opset_import.extend([helper.make_opsetid("", OPSET)])
    model.producer_name = "mannequin tools/person_models/convert.py (tf2onnx 1.17)"
    model.graph.name = os.path.basename(tflite_model).replace(".tflite", "")
    model.doc_string = source


def tflite_input_output_names(model):
    from tensorflow.lite.tools import flatbuffer_utils
    graph = flatbuffer_utils.read_model(tflite_path(model)).subgraphs[0]
    names = lambda indices: [graph.tensors[i].name.decode() for i in indices]
    return names(graph.inputs), names(graph.outputs)


def check(model, shapes):
    """Checker, strict shape inference with the expected fixed shapes, standard ops, f32 weights."""
    onnx.checker.check_model(model, full_check=True)
    inferred = onnx.shape_inference.infer_shapes(model, strict_mode=True)
    for value in list(inferred.graph.input) + list(inferred.graph.output):
        dims = [d.dim_value if d.HasField("dim_value") else None for d in value.type.tensor_type.shape.dim]
        assert dims == shapes[value.name], (value.name, dims, shapes[value.name])
        assert value.type.tensor_type.elem_type == onnx.TensorProto.FLOAT
    assert all(n.domain in ("", "ai.onnx") for n in model.graph.node)
    assert all(t.data_type in (onnx.TensorProto.FLOAT, onnx.TensorProto.INT64)
               for t in model.graph.initializer)
    return sorted({n.op_type for n in model.graph.node})


def onnxruntime_outputs(path, x):
    session = onnxruntime.InferenceSession(path, providers=["CPUExecutionProvider"])
    names = [o.name for o in session.get_outputs()]
    return dict(zip(names, session.run(names, {"input": x})))


def write_models(out_dir):
    os.makedirs(out_dir, exist_ok=True)
    wheel = wheel_name()
    notes = []
    for model, changes in [
        (DETECTION, "sparse fp16 weights (DENSIFY + DEQUANTIZE) materialised as float32 constants "
                    "by the TFLite interpreter; that dense TFLite graph converted by tf2onnx"),
        (LANDMARK, "converted by tf2onnx (fp16 weights DEQUANTIZEd to float32 constants)"),
        (SELFIE, "converted by tf2onnx; MediaPipe's custom op Convolution2DTransposeBias replaced "
                 "by ConvTranspose (kernel 2, stride 2, weights [out,kh,kw,in] -> [in,out,kh,kw], "
                 "bias) followed by an NCHW -> NHWC Transpose"),
        (FACE_DETECTION, "converted by tf2onnx (fp16 weights DEQUANTIZEd to float32 constants)"),
        (FACE_LANDMARK, "converted by tf2onnx (fp16 weights DEQUANTIZEd to float32 constants)"),
    ]:
        name = os.path.basename(model).replace(".tflite", ".onnx")
        digest = sha256(tflite_path(model))
        source = f"{wheel}: mediapipe/modules/{model} (sha256 {digest}), Apache-2.0"
        if model == DETECTION:
            with tempfile.TemporaryDirectory() as tmp:
                dense = os.path.join(tmp, "pose_detection_dense.tflite")
                dense_detection_tflite(dense)
                onnx_model = tf2onnx_convert(dense)
        else:
            onnx_model = tf2onnx_convert(tflite_path(model))
        if model == SELFIE:
            replace_transpose_conv_bias(onnx_model)
        tidy(onnx_model, model, source)
        path = os.path.join(out_dir, name)
        onnx.save(onnx_model, path)
        shapes = {v.name: [d.dim_value for d in v.type.tensor_type.shape.dim]
                  for v in list(onnx_model.graph.input) + list(onnx_model.graph.output)}
        ops = check(onnx_model, shapes)
        diffs = compare(model, path)
        print(f"{name}: {os.path.getsize(path)} bytes, shapes {shapes}")
        print(f"  ops {ops}")
        for image, d in diffs.items():
            print(f"  max |onnxruntime - tflite| on {image}: " +
                  ", ".join(f"{k} {v:.3g}" for k, v in d.items()))
        notes.append((name, model, digest, changes, shapes, ops))
    copy_licence(out_dir)
    write_notice(out_dir, wheel, notes)


def compare(model, onnx_path):
    diffs = {}
    for image in IMAGES:
        x = model_input(model, image)
        want = run_tflite(model, x)
        got = onnxruntime_outputs(onnx_path, x)
        diffs[image] = {k: float(np.abs(got[k] - want[k]).max()) for k in want}
    return diffs


def wheel_name():
    dist = importlib.metadata.distribution(WHEEL)
    tag = [line.split(": ")[1] for line in dist.read_text("WHEEL").splitlines()
           if line.startswith("Tag:")][0]
    return f"{WHEEL}-{dist.version}-{tag}.whl (PyPI)"


def sha256(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def copy_licence(out_dir):
    dist = importlib.metadata.distribution(WHEEL)
    text = dist.read_text("LICENSE")
    assert "Apache License" in text and "Version 2.0" in text
    with open(os.path.join(out_dir, "LICENSE"), "w") as f:
        f.write(text)


def write_notice(out_dir, wheel, notes):
    lines = [
        "# Person models: where they come from",
        "",
        "These ONNX files are converted from the TFLite models of Google's MediaPipe, "
        "Copyright The MediaPipe Authors, licensed under the Apache License 2.0 (`LICENSE` beside "
        "this file, as found in the wheel's `mediapipe-0.10.21.dist-info/LICENSE`). They are "
        "modified versions: the changes are listed per file. Made by "
        "`tools/person_models/convert.py models` (tf2onnx 1.17.0, opset 17).",
        "",
        f"Source wheel: `{wheel}`.",
        "",
        "Common to all: converted from TFLite to ONNX opset 17; the input renamed `input` "
        "(NHWC float32, fixed shape as the original), the outputs renamed as below; weights "
        "stored as float32.",
        "",
    ]
    for name, model, digest, changes, shapes, ops in notes:
        lines += [
            f"## `{name}`",
            "",
            f"- from `mediapipe/modules/{model}`, sha256 `{digest}`",
            f"- changes: {changes}",
            f"- input `input` {shapes['input']}; outputs " + ", ".join(
                f"`{o}` {shapes[o]}" for o in OUTPUT_NAMES[model]),
            f"- operators: {', '.join(ops)}",
            "",
        ]
    with open(os.path.join(out_dir, "NOTICE.md"), "w") as f:
        f.write("\n".join(lines))


# --- fixtures --------------------------------------------------------------------------------

def picture_path(image):
    import skimage.data
    return os.path.join(os.path.dirname(skimage.data.__file__), f"{image}.png")


def picture(image):
    """scikit-image's 512² picture as RGB uint8 (the grey camera with its channel repeated)."""
    return np.asarray(Image.open(picture_path(image)).convert("RGB"))


def resized(image, size):
    return np.asarray(Image.fromarray(picture(image)).resize((size, size), Image.BILINEAR))


def model_input(model, image):
    side, divisor, offset = INPUTS[model]
    return (resized(image, side).astype(np.float32) / divisor + offset)[None]


def write_fixtures(out_dir):
    os.makedirs(out_dir, exist_ok=True)
    for image in IMAGES:
        for prefix, model in [("detection", DETECTION), ("landmark", LANDMARK), ("selfie", SELFIE),
                              ("face_detection", FACE_DETECTION), ("face_landmark", FACE_LANDMARK)]:
            outputs = run_tflite(model, model_input(model, image))
            outputs.pop("heatmaps", None)
            save(out_dir, f"{prefix}_{image}.npz", input_u8=resized(image, INPUTS[model][0]),
                 **{k: v.astype(np.float32) for k, v in outputs.items()})
        save(out_dir, f"pipeline_{image}.npz", **pipeline(picture(image)))
        save(out_dir, f"face_pipeline_{image}.npz", **face_pipeline(picture(image)))
        shutil.copyfile(picture_path(image), os.path.join(out_dir, f"{image}.png"))
    save(out_dir, "face_track_astronaut.npz", **face_track(picture("astronaut")))
    write_provenance(out_dir)


# What scikit-image says of its pictures (their docstrings; skimage/data/README.txt says nothing).
PICTURE_NOTES = {
    "astronaut": ["Photograph of Eileen Collins, an American astronaut.",
                  "This image was downloaded from the NASA Great Images database",
                  "<https://flic.kr/p/r9qvLn>`__.",
                  "No known copyright restrictions, released into the public domain."],
    "camera": ["Gray-level \"camera\" image.",
               "No copyright restrictions. CC0 by the photographer (Lav Varshney).",
               "This image was replaced due to copyright restrictions. For more",
               "information, please see [1]_.",
               ".. [1] https://github.com/scikit-image/scikit-image/issues/3927"],
}


# A third portrait, for the face fit only (no fixture is made from it).
GRACE_HOPPER = [
    "## `grace_hopper.jpg`",
    "",
    "Copied unchanged from matplotlib 3.11.2 (PyPI wheel), "
    "`matplotlib/mpl-data/sample_data/grace_hopper.jpg`, sha256 "
    "`a8ca6d734765703b09728ab47fe59f473d93ae3967fc24c7c0288c3c7adb7130`: the official US Navy "
    "portrait of Commodore Grace M. Hopper, a work of the US federal government and so in the "
    "public domain (Wikimedia Commons lists it as \"Commodore Grace M. Hopper, USN (covered)\"). "
    "512 × 600, JPEG.",
    "",
]


def write_provenance(out_dir):
    import skimage
    import skimage.data
    lines = ["# Person-model test pictures and golden fixtures", ""]
    for image, quotes in PICTURE_NOTES.items():
        doc = getattr(skimage.data, image).__doc__
        assert all(q in doc for q in quotes), image
        lines += [
            f"## `{image}.png`",
            "",
            f"Copied unchanged from scikit-image {skimage.__version__} (PyPI wheel), "
            f"`skimage/data/{image}.png`, sha256 `{sha256(picture_path(image))}`. "
            f"`skimage.data.{image}` says:",
            "",
        ] + [f"> {q}" for q in quotes] + [""]
    lines += GRACE_HOPPER + [
        "## Fixtures",
        "",
        "Made by `tools/person_models/convert.py fixtures` (see its docstring) from the original "
        "TFLite models of the `mediapipe==0.10.21` wheel. The grey `camera` is made RGB by "
        "repeating its channel. `input_u8` is the 512² picture resized with Pillow's "
        "`Image.resize((n, n), Image.BILINEAR)` (which antialiases when it shrinks).",
        "",
        "- `detection_<image>.npz`: `input_u8` [224,224,3]; the model fed input_u8 / 127.5 - 1; "
        "`regressors` [1,2254,12], `scores` [1,2254,1] (logits).",
        "- `landmark_<image>.npz`: `input_u8` [256,256,3]; fed input_u8 / 255; `landmarks` "
        "[1,195], `pose_flag` [1,1] (a probability: the model ends in a sigmoid), `mask` "
        "[1,256,256,1] (logits), `world_landmarks` [1,117]; `heatmaps` left out.",
        "- `selfie_<image>.npz`: `input_u8` [256,256,3]; fed input_u8 / 255; `mask` [1,256,256,1] "
        "(a probability), run in MediaPipe's runtime (its custom op).",
        "- `pipeline_<image>.npz`: MediaPipe's legacy `Pose(static_image_mode=True, "
        "model_complexity=1, enable_segmentation=True)` graph on the 512² RGB picture: `found` [1] "
        "(1.0 or 0.0; nothing else when 0), `landmarks_norm` [33,5] (x, y, z, visibility, presence "
        "as MediaPipe gives them: x, y in [0,1] of the image, z on x's scale), `landmarks_px` "
        "(the same with x, z times the width and y times the height), `world_landmarks` [33,3] "
        "(metres, hip-centred), `segmentation` [512,512] (probability), `detection` [13] (the "
        "person detection that seeded it: score, xmin, ymin, width, height, then 4 keypoints "
        "x, y, all relative to the image), `roi` [5] (the landmark crop it made from that "
        "detection: x_center, y_center, width, height relative to the image, rotation in "
        "radians). Replayed with the ONNX models here, it matched to 0.33 px only with a 9x9 "
        "heatmap refinement window: MediaPipe 0.10.21 behaves as RefineLandmarksFromHeatmap's "
        "default kernel_size 9, though its graph sets 7.",
        "- `face_detection_<image>.npz`: `input_u8` [128,128,3]; fed input_u8 / 127.5 - 1; "
        "`regressors` [1,896,16], `scores` [1,896,1] (logits).",
        "- `face_landmark_<image>.npz`: `input_u8` [192,192,3] (the whole picture, not a face "
        "crop: a check of the network, not of the crop); fed input_u8 / 255; `landmarks` "
        "[1,1,1,1404] (crop pixels), `face_flag` [1,1,1,1] (a logit).",
        "- `face_pipeline_<image>.npz`: MediaPipe's legacy `FaceMesh(static_image_mode=True, "
        "max_num_faces=1, refine_landmarks=False)` graph on the 512² RGB picture: `found` [1], "
        "`landmarks_norm` [468,3] (x, y in [0,1] of the image, z on x's scale), `landmarks_px` "
        "(x, z times the width, y times the height), `detection` [17] (score, xmin, ymin, width, "
        "height, then 6 keypoints x, y, relative to the image), `roi` [5] (the mesh crop made "
        "from that detection: x_center, y_center, width, height relative, rotation in radians).",
        "- `face_track_astronaut.npz`: the same graph in video mode (`static_image_mode=False`, so "
        "each crop after the first comes from the previous frame's landmarks) over 448² windows of "
        "`astronaut.png` at `offsets` [8,2] (x, y of the window's corner): `landmarks_px` [8,468,3] "
        "in the window's pixels (z times its width), `next_roi_px` [8,5] (the crop each frame's "
        "landmarks make for the next: x_center, y_center, width, height in pixels, rotation).",
        "",
    ]
    with open(os.path.join(out_dir, "PROVENANCE.md"), "w") as f:
        f.write("\n".join(lines))


def save(out_dir, name, **arrays):
    path = os.path.join(out_dir, name)
    np.savez_compressed(path, **arrays)
    print(f"{name}: {os.path.getsize(path)} bytes, " +
          ", ".join(f"{k} {list(v.shape)} {v.dtype}" for k, v in arrays.items()))


def pipeline(rgb):
    """mp.solutions.pose.Pose(static_image_mode=True, model_complexity=1,
    enable_segmentation=True), through its SolutionBase with the same graph, side inputs and
    parameters, asking for the detection and its ROI too, and keeping `presence` (Pose.process
    clears it)."""
    from mediapipe.python.solution_base import SolutionBase
    from mediapipe.python.solutions import pose
    solution = SolutionBase(
        binary_graph_path=pose._BINARYPB_FILE_PATH,
        side_inputs={"model_complexity": 1, "smooth_landmarks": False, "enable_segmentation": True,
                     "smooth_segmentation": False, "use_prev_landmarks": False},
        calculator_params={
            "posedetectioncpu__TensorsToDetectionsCalculator.min_score_thresh": 0.5,
            "poselandmarkbyroicpu__tensorstoposelandmarksandsegmentation__ThresholdingCalculator.threshold": 0.5},
        outputs=["pose_landmarks", "pose_world_landmarks", "segmentation_mask", "pose_detection",
                 "pose_rect_from_detection"])
    with solution:
        r = solution.process({"image": rgb})
    h, w = rgb.shape[:2]
    out = {"found": np.array([float(r.pose_landmarks is not None)], np.float32)}
    if r.pose_landmarks is None:
        return out
    lm = r.pose_landmarks.landmark
    out["landmarks_norm"] = np.array([[p.x, p.y, p.z, p.visibility, p.presence] for p in lm], np.float32)
    out["landmarks_px"] = out["landmarks_norm"] * np.array([w, h, w, 1, 1], np.float32)
    out["world_landmarks"] = np.array(
        [[p.x, p.y, p.z] for p in r.pose_world_landmarks.landmark], np.float32)
    if r.segmentation_mask is not None:
        out["segmentation"] = np.asarray(r.segmentation_mask, np.float32).reshape(h, w)
    d = r.pose_detection
    box = d.location_data.relative_bounding_box
    out["detection"] = np.array(
        [d.score[0], box.xmin, box.ymin, box.width, box.height] +
        [v for k in d.location_data.relative_keypoints for v in (k.x, k.y)], np.float32)
    roi = r.pose_rect_from_detection
    out["roi"] = np.array([roi.x_center, roi.y_center, roi.width, roi.height, roi.rotation], np.float32)
    return out


def face_mesh_solution(use_prev_landmarks, outputs):
    """The legacy FaceMesh solution's graph (max_num_faces=1, refine_landmarks=False) through its
    SolutionBase, with the same side inputs and parameters, asking for `outputs`; with
    `use_prev_landmarks` it is FaceMesh(static_image_mode=False)."""
    from mediapipe.python.solution_base import SolutionBase
    from mediapipe.python.solutions import face_mesh
    return SolutionBase(
        binary_graph_path=face_mesh._BINARYPB_FILE_PATH,
        side_inputs={"num_faces": 1, "with_attention": False, "use_prev_landmarks": use_prev_landmarks},
        calculator_params={
            "facedetectionshortrangecpu__facedetectionshortrange__facedetection__TensorsToDetectionsCalculator.min_score_thresh": 0.5,
            "facelandmarkcpu__ThresholdingCalculator.threshold": 0.5},
        outputs=outputs)


def face_pipeline(rgb):
    """mp.solutions.face_mesh.FaceMesh(static_image_mode=True, max_num_faces=1,
    refine_landmarks=False), through its SolutionBase with the same graph, side inputs and
    parameters, asking for the face detection and the crop it made too."""
    solution = face_mesh_solution(False, ["multi_face_landmarks", "face_detections", "face_rects_from_detections"])
    with solution:
        r = solution.process({"image": rgb})
    h, w = rgb.shape[:2]
    out = {"found": np.array([float(bool(r.multi_face_landmarks))], np.float32)}
    if not r.multi_face_landmarks:
        return out
    lm = r.multi_face_landmarks[0].landmark
    out["landmarks_norm"] = np.array([[p.x, p.y, p.z] for p in lm], np.float32)
    out["landmarks_px"] = out["landmarks_norm"] * np.array([w, h, w], np.float32)
    d = r.face_detections[0]
    box = d.location_data.relative_bounding_box
    out["detection"] = np.array(
        [d.score[0], box.xmin, box.ymin, box.width, box.height] +
        [v for k in d.location_data.relative_keypoints for v in (k.x, k.y)], np.float32)
    roi = r.face_rects_from_detections[0]
    out["roi"] = np.array([roi.x_center, roi.y_center, roi.width, roi.height, roi.rotation], np.float32)
    return out


# A "video" of astronaut.png: 448² windows of it at these (x, y) offsets, so the face moves by
# whole pixels from frame to frame.
TRACK_WINDOW = 448
TRACK_OFFSETS = [(32, 32), (40, 30), (48, 28), (56, 30), (60, 36), (52, 44), (40, 48), (30, 40)]


def face_track(rgb):
    """mp.solutions.face_mesh.FaceMesh(static_image_mode=False, max_num_faces=1,
    refine_landmarks=False) over the windows: after the first frame each crop comes from the
    previous frame's landmarks (MediaPipe's tracking)."""
    solution = face_mesh_solution(True, ["multi_face_landmarks", "face_rects_from_landmarks"])
    n = TRACK_WINDOW
    landmarks, rois = [], []
    with solution:
        for x, y in TRACK_OFFSETS:
            frame = np.ascontiguousarray(rgb[y:y + n, x:x + n])
            r = solution.process({"image": frame})
            lm = r.multi_face_landmarks[0].landmark
            landmarks.append([[p.x * n, p.y * n, p.z * n] for p in lm])
            roi = r.face_rects_from_landmarks[0]
            rois.append([roi.x_center * n, roi.y_center * n, roi.width * n, roi.height * n, roi.rotation])
    return {"offsets": np.array(TRACK_OFFSETS, np.float32), "window": np.array([n], np.float32),
            "landmarks_px": np.array(landmarks, np.float32), "next_roi_px": np.array(rois, np.float32)}


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] not in ("models", "fixtures"):
        sys.exit(__doc__)
    {"models": write_models, "fixtures": write_fixtures}[sys.argv[1]](sys.argv[2])
