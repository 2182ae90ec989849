"""BlazePose with onnxruntime: person detector, landmark model and a MediaPipe-like tracker."""
