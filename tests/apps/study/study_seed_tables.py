"""The seed's Tables 6.1 (video study) and 6.2 (in-person study), typed in as test data.

Rows/columns: Face, Hand, L-FH, S-FH; cell (i, j) = participants (of 24) preferring i over j,
averaged over both ordered comparisons. ``P`` is the table's P_i column (two decimals).
"""

CONDITIONS = ["Face", "Hand", "L-FH", "S-FH"]
N_PARTICIPANTS = 24

TABLE_6_1 = {
    "likability": {
        "wins": [
            [0, 6.75, 2.75, 2.25],
            [17.25, 0, 3.5, 4.75],
            [21.25, 20.5, 0, 8],
            [21.75, 19.25, 16, 0],
        ],
        "a": [11.75, 25.5, 49.75, 57],
        "P": [0.04, 0.09, 0.34, 0.52],
    },
    "anthropomorphism": {
        "wins": [[0, 5, 3.5, 3.25], [19, 0, 5, 4.75], [20.5, 19, 0, 8.5], [20.75, 19.25, 15.5, 0]],
        "a": [11.75, 28.75, 48, 55.5],
        "P": [0.05, 0.12, 0.33, 0.50],
    },
    "timing-communication": {
        "wins": [[0, 5.5, 3, 2], [18.5, 0, 3.5, 4], [21, 20.5, 0, 7], [22, 20, 17, 0]],
        "a": [10.5, 26, 48.5, 59],
        "P": [0.03, 0.09, 0.31, 0.57],
    },
}

TABLE_6_2 = {
    "likability": {
        "wins": [[0, 15, 14.5, 15.75], [9, 0, 7, 7.75], [9.5, 17, 0, 13], [8.25, 16.25, 11, 0]],
        "a": [45.25, 23.75, 39.5, 35.5],
        "P": [0.35, 0.14, 0.28, 0.23],
        "p_value": 0.01,
    },
    "anthropomorphism": {
        "wins": [
            [0, 14.25, 13, 15],
            [9.75, 0, 6.75, 7.5],
            [11, 17.25, 0, 13.25],
            [9, 16.5, 10.75, 0],
        ],
        "a": [42.25, 24, 41.5, 36.25],
        "P": [0.31, 0.14, 0.30, 0.24],
        "p_value": 0.03,
    },
    "timing-communication": {
        "wins": [[0, 11.5, 11.5, 13.5], [12.5, 0, 7, 8.5], [12.5, 17, 0, 13], [10.5, 15.5, 11, 0]],
        "a": [36.5, 28, 42.5, 37],
        "P": [0.25, 0.17, 0.32, 0.25],
        "p_value": 0.21,
    },
}
