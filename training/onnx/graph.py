"""A small helper for ONNX step graphs written directly with onnx.helper (the generator and refiner exports):
initialisers and nodes collected in order, float inputs/outputs with symbolic dims, one checked model."""
from __future__ import annotations

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

OPSET = 17


class GraphBuilder:
    def __init__(self) -> None:
        self.inits: list[onnx.TensorProto] = []
        self.nodes: list[onnx.NodeProto] = []

    def const(self, name: str, value: np.ndarray) -> str:
        """An initialiser; returns its name."""
        self.inits.append(numpy_helper.from_array(np.ascontiguousarray(value), name))
        return name

    def node(self, op: str, inputs: list[str], outputs: list[str], **attrs):
        """Adds a node; returns its output name (or names, when several)."""
        self.nodes.append(helper.make_node(op, inputs, outputs, **attrs))
        return outputs[0] if len(outputs) == 1 else outputs

    def model(self, name: str, inputs: list[tuple[str, list]], outputs: list[tuple[str, list]], producer: str) -> onnx.ModelProto:
        """The graph as a checked model; inputs and outputs are (name, shape) float tensors."""
        value = lambda n, shape: helper.make_tensor_value_info(n, TensorProto.FLOAT, shape)
        graph = helper.make_graph(self.nodes, name, [value(*i) for i in inputs], [value(*o) for o in outputs], self.inits)
        model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", OPSET)], producer_name=producer)
        model.ir_version = 8
        onnx.checker.check_model(model, full_check=True)
        return model
