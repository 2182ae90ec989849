"""Everyone in view: person boxes, their motion, association and the multi-person tracker."""
