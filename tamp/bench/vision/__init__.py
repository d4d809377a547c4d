"""The benchmarks of seeing: perception's relation accuracy and planning from images
(`perception`), LatPlan-40 from its own images (`latplan`), block poses from RGB-D images
against the true poses (`poses`), and the colour segmentation's thresholds checked on fresh
renders (`segmentation`). They share the planning benchmarks' results writer and tables."""
