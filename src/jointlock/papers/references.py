"""The seed papers: title, authors, venue and DOI of each, to cite them from the docs, the
reports and ``jointlock reproduce``.

Our copies of 000, 001 and 002 begin at the abstract, so their titles and authors are taken
from the publishers' pages (the DOIs below); 004's copy prints them.  001's page names its
authors as "Qingxuan Jia et al." only.
"""

from __future__ import annotations

#: Seed -> its reference, one line (authors, "title", venue, year, DOI).
REFERENCES: dict[str, str] = {
    "000": (
        'Gang Chen, Lanpu Li, Yingzhuo Fu, Bonan Yuan, Junting Fei, "Halt Optimization Strategy for a '
        'Space Manipulator with a Joint-Locked Failure", International Journal of Aerospace Engineering, '
        "vol. 2020, Article ID 8811433, 2020. doi:10.1155/2020/8811433"
    ),
    "001": (
        'Qingxuan Jia et al., "Trajectory Optimization for Velocity Jumps Reduction considering the '
        'Unexpectedness Characteristics of Space Manipulator Joint-Locked Failure", International Journal '
        "of Aerospace Engineering, vol. 2016, Article ID 7819540, 2016. doi:10.1155/2016/7819540"
    ),
    "002": (
        'Zonggao Mu, Liang Han, Wenfu Xu, Bing Li, Bin Liang, "Kinematic Analysis and Fault-Tolerant '
        'Trajectory Planning of Space Manipulator Under a Single Joint Failure", Robotics and Biomimetics, '
        "vol. 3, article 16, 2016. doi:10.1186/s40638-016-0048-9"
    ),
    "004": (
        'Gang Chen, Long Zhang, Qingxuan Jia, Hanxu Sun, "Singularity Analysis of Redundant Space Robot '
        'with the Structure of Canadarm2", Mathematical Problems in Engineering, vol. 2014, Article ID '
        "735030, 2014. doi:10.1155/2014/735030"
    ),
}
